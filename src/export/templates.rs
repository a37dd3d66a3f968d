//! The editable templates (`templates/*.j2`, built in; a folder given with `--templates` overrides
//! them file by file). Values are escaped for XML by the engine.

use crate::error::{Error, Result};
use std::path::Path;

const BUILTIN: &[(&str, &str)] = &[
    ("scene.xml.j2", include_str!("../../templates/scene.xml.j2")),
    (
        "object.xml.j2",
        include_str!("../../templates/object.xml.j2"),
    ),
    (
        "object.urdf.j2",
        include_str!("../../templates/object.urdf.j2"),
    ),
    (
        "scene.usda.j2",
        include_str!("../../templates/scene.usda.j2"),
    ),
    (
        "object.usda.j2",
        include_str!("../../templates/object.usda.j2"),
    ),
];

pub struct Templates {
    env: minijinja::Environment<'static>,
}

impl Templates {
    /// Built-in templates, each overridden by a file of the same name in `dir` if present.
    pub fn load(dir: Option<&Path>) -> Result<Templates> {
        let mut env = minijinja::Environment::new();
        env.set_undefined_behavior(minijinja::UndefinedBehavior::Strict);
        // Every value is escaped for XML (URDF and MJCF alike): & < > " ' only. USD templates'
        // values are written as they are: the writer hands them over as USD text already
        // (identifiers, numbers, tuples).
        env.set_auto_escape_callback(|_| minijinja::AutoEscape::None);
        env.set_formatter(|out, state, value| {
            let s = value.to_string();
            if state.name().ends_with(".usda.j2") {
                return out.write_str(&s).map_err(minijinja::Error::from);
            }
            let mut e = String::with_capacity(s.len());
            for c in s.chars() {
                match c {
                    '&' => e.push_str("&amp;"),
                    '<' => e.push_str("&lt;"),
                    '>' => e.push_str("&gt;"),
                    '"' => e.push_str("&quot;"),
                    '\'' => e.push_str("&apos;"),
                    c => e.push(c),
                }
            }
            out.write_str(&e).map_err(minijinja::Error::from)
        });
        for (name, builtin) in BUILTIN {
            let source = match dir.map(|d| d.join(name)).filter(|p| p.is_file()) {
                Some(p) => std::fs::read_to_string(&p).map_err(|e| Error::io(&p, e))?,
                None => builtin.to_string(),
            };
            env.add_template_owned(name.to_string(), source)
                .map_err(|e| {
                    Error::input(
                        dir.map(|d| d.join(name)).unwrap_or_else(|| name.into()),
                        format!("template error: {e}"),
                    )
                })?;
        }
        Ok(Templates { env })
    }

    /// Render a template with a context.
    pub fn render(&self, name: &str, ctx: minijinja::Value) -> Result<String> {
        self.env
            .get_template(name)
            .and_then(|t| t.render(ctx))
            .map_err(|e| Error::Usage(format!("template {name}: {e:#}")))
    }
}
