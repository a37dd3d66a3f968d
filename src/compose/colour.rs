//! Colour as a tie-breaker for symmetric shapes (a box registered upside down fits the geometry
//! as well as the right way up; its print does not). Colours are made gain-invariant (each
//! channel divided by the cloud's mean) because a generated scene's texture is lit and tinted
//! differently from the user's mesh; the hypothesis score then weights each geometric inlier by
//! the agreement of the two colours (see [`super::global::score`]).

use super::cloud::Cloud;

/// Divide each channel by its mean over the cloud (at least 0.05, so dark channels do not blow up
/// noise), then scale to a mean brightness of 0.5.
pub fn normalise(c: &mut Cloud) {
    if c.colours.is_empty() {
        return;
    }
    let n = c.colours.len() as f64;
    let mut mean = [0.0; 3];
    for col in &c.colours {
        for k in 0..3 {
            mean[k] += col[k] / n;
        }
    }
    for col in &mut c.colours {
        for k in 0..3 {
            col[k] = 0.5 * col[k] / mean[k].max(0.05);
        }
    }
}

/// Whether colour can help: both clouds vary in colour.
pub fn usable(object: &Cloud, guidance: &Cloud) -> bool {
    object.has_colour_variation() && guidance.has_colour_variation()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gain_does_not_change_normalised_colours() {
        let mut a = Cloud {
            colours: vec![[0.2, 0.4, 0.1], [0.6, 0.2, 0.3], [0.1, 0.1, 0.9]],
            ..Cloud::default()
        };
        let mut b = a.clone();
        for c in &mut b.colours {
            c[0] *= 0.8;
            c[1] *= 1.1;
            c[2] *= 0.9;
        }
        normalise(&mut a);
        normalise(&mut b);
        for (x, y) in a.colours.iter().zip(&b.colours) {
            for k in 0..3 {
                assert!((x[k] - y[k]).abs() < 1e-12);
            }
        }
    }
}
