//! `--shard auto`: the shard index and count read from a cluster scheduler's environment.
//!
//! Entry point: [`shard_from_env`] (with [`std_env`] as the usual lookup). Supported:
//!
//! * **Slurm job arrays**: `SLURM_ARRAY_TASK_ID`, with `SLURM_ARRAY_TASK_MIN` and
//!   `SLURM_ARRAY_TASK_MAX` and/or `SLURM_ARRAY_TASK_COUNT` (and `SLURM_ARRAY_TASK_STEP`). The
//!   array may start at 0, 1 or anywhere (`--array=0-9`, `--array=1-10`, `--array=0-18:2`); the
//!   task at MIN is shard 1. Lists with gaps (`--array=1,4,9`) are refused: their ids do not map
//!   onto 1..=N.
//! * **Kubernetes Indexed Jobs**: `JOB_COMPLETION_INDEX` (0-based); the count, which Kubernetes
//!   does not put in the environment, from `--shards N` or `INTERACT3D_SHARDS`.
//! * **AWS Batch array jobs**: `AWS_BATCH_JOB_ARRAY_INDEX` (0-based); the count (the array
//!   size) from `--shards N` or `INTERACT3D_SHARDS`.
//!
//! `--shards N` (or `INTERACT3D_SHARDS`) given beside a Slurm array must agree with its size.

use super::discover::Shard;
use crate::error::{Error, Result};

/// The environment variable that gives the shard count where the scheduler does not.
pub const SHARDS_VAR: &str = "INTERACT3D_SHARDS";

/// The variables that `--shard auto` looks at, for error messages and docs.
pub const INDEX_VARS: [&str; 3] = [
    "SLURM_ARRAY_TASK_ID",
    "JOB_COMPLETION_INDEX",
    "AWS_BATCH_JOB_ARRAY_INDEX",
];

/// A shard found in the environment, and where it came from (one line for the log).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Detected {
    pub shard: Shard,
    pub source: String,
}

/// `--shard`: a fixed `I/N`, or `auto` (from the scheduler's environment).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShardArg {
    Fixed(Shard),
    Auto,
}

impl std::str::FromStr for ShardArg {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        if s.trim().eq_ignore_ascii_case("auto") {
            Ok(ShardArg::Auto)
        } else {
            s.parse()
                .map(ShardArg::Fixed)
                .map_err(|e| format!("{e}, or auto (from Slurm, Kubernetes or AWS Batch)"))
        }
    }
}

impl ShardArg {
    /// The shard to run: a fixed one as given (`--shards` must then agree, if given), `auto`
    /// from this process's environment.
    pub fn resolve(self, shards: Option<usize>) -> Result<Detected> {
        match self {
            ShardArg::Fixed(shard) => {
                if let Some(n) = shards.filter(|&n| n != shard.count) {
                    return Err(Error::Usage(format!(
                        "--shard {shard} and --shards {n} disagree"
                    )));
                }
                Ok(Detected {
                    shard,
                    source: format!("--shard {shard}"),
                })
            }
            ShardArg::Auto => shard_from_env(&std_env, shards),
        }
    }
}

/// Look variables up in this process's environment.
pub fn std_env(name: &str) -> Option<String> {
    std::env::var(name).ok()
}

/// The shard for `--shard auto`. `shards` is `--shards N`; `env` looks a variable up (tests pass
/// a map). Errors (exit 2) name the variables that were expected or are inconsistent.
pub fn shard_from_env(
    env: &dyn Fn(&str) -> Option<String>,
    shards: Option<usize>,
) -> Result<Detected> {
    let get = |name: &str| env(name).filter(|v| !v.trim().is_empty());
    let set: Vec<&str> = INDEX_VARS
        .iter()
        .copied()
        .filter(|v| get(v).is_some())
        .collect();
    let count_from_var = match get(SHARDS_VAR) {
        None => None,
        Some(v) => Some(number(SHARDS_VAR, &v)?),
    };
    let given_count = match (shards, count_from_var) {
        (Some(n), Some(m)) if n != m => {
            return Err(Error::Usage(format!(
                "--shards {n} and {SHARDS_VAR}={m} disagree"
            )))
        }
        (Some(n), _) | (None, Some(n)) => Some(n),
        (None, None) => None,
    };
    match set.as_slice() {
        [] => Err(Error::Usage(format!(
            "--shard auto: no scheduler found in the environment: none of {} is set \
             (Slurm job array, Kubernetes Indexed Job, AWS Batch array job); \
             pass --shard I/N instead",
            INDEX_VARS.join(", ")
        ))),
        ["SLURM_ARRAY_TASK_ID"] => slurm(&get, given_count),
        [var] => zero_based(var, &get(var).unwrap_or_default(), given_count),
        several => Err(Error::Usage(format!(
            "--shard auto: {} are all set; cannot tell which scheduler runs this task \
             (unset the others or pass --shard I/N)",
            several.join(" and ")
        ))),
    }
}

fn number(name: &str, v: &str) -> Result<usize> {
    v.trim()
        .parse::<usize>()
        .map_err(|_| Error::Usage(format!("--shard auto: {name}={v:?} is not a whole number")))
}

fn check(shard: Shard, source: String) -> Result<Detected> {
    if shard.count == 0 || shard.index == 0 || shard.index > shard.count {
        return Err(Error::Usage(format!(
            "--shard auto: {source} gives shard {}/{}, outside 1..={}",
            shard.index, shard.count, shard.count
        )));
    }
    Ok(Detected { shard, source })
}

/// Kubernetes and AWS Batch: a 0-based index, the count from `--shards`/`INTERACT3D_SHARDS`.
fn zero_based(var: &str, value: &str, count: Option<usize>) -> Result<Detected> {
    let index = number(var, value)?;
    let Some(count) = count else {
        return Err(Error::Usage(format!(
            "--shard auto: {var}={index} is set but not how many shards there are; \
             pass --shards N or set {SHARDS_VAR}=N (the Job's completions / the array size)"
        )));
    };
    check(
        Shard {
            index: index + 1,
            count,
        },
        format!("{var}={index} (0-based), {count} shards"),
    )
}

/// Slurm: index relative to the array's first id, count from MIN/MAX/STEP or COUNT.
fn slurm(get: &dyn Fn(&str) -> Option<String>, given: Option<usize>) -> Result<Detected> {
    let var =
        |name: &str| -> Result<Option<usize>> { get(name).map(|v| number(name, &v)).transpose() };
    let id = var("SLURM_ARRAY_TASK_ID")?.expect("checked by the caller");
    let min = var("SLURM_ARRAY_TASK_MIN")?;
    let max = var("SLURM_ARRAY_TASK_MAX")?;
    let step = var("SLURM_ARRAY_TASK_STEP")?.unwrap_or(1).max(1);
    let count = var("SLURM_ARRAY_TASK_COUNT")?;
    let min = match (min, max, count) {
        (Some(min), _, _) => min,
        (None, Some(max), Some(count)) if count >= 1 && max >= (count - 1) * step => {
            max - (count - 1) * step
        }
        _ => {
            return Err(Error::Usage(
                "--shard auto: SLURM_ARRAY_TASK_ID is set but not SLURM_ARRAY_TASK_MIN \
                 (nor MAX with COUNT), so the array's first id (0 or 1) is unknown; \
                 run under sbatch --array, or pass --shard I/N"
                    .into(),
            ))
        }
    };
    let span = max.map(|max| (max.saturating_sub(min)) / step + 1);
    let n = match (span, count) {
        (Some(a), Some(b)) if a != b => {
            return Err(Error::Usage(format!(
                "--shard auto: the Slurm array is not a plain range (SLURM_ARRAY_TASK_COUNT={b} \
                 but MIN..MAX step {step} holds {a} ids); use --array=A-B (or A-B:S) so the \
                 task ids map onto shards 1..=N"
            )))
        }
        (Some(n), _) | (None, Some(n)) => n,
        (None, None) => given.ok_or_else(|| {
            Error::Usage(
                "--shard auto: SLURM_ARRAY_TASK_ID is set but neither SLURM_ARRAY_TASK_MAX \
                 nor SLURM_ARRAY_TASK_COUNT; pass --shards N"
                    .into(),
            )
        })?,
    };
    if let Some(g) = given {
        if g != n {
            return Err(Error::Usage(format!(
                "--shard auto: the Slurm array has {n} tasks but --shards/{SHARDS_VAR} says {g}"
            )));
        }
    }
    if id < min || (id - min) % step != 0 {
        return Err(Error::Usage(format!(
            "--shard auto: SLURM_ARRAY_TASK_ID={id} is not in the array {min}..(step {step})"
        )));
    }
    check(
        Shard {
            index: (id - min) / step + 1,
            count: n,
        },
        format!(
            "Slurm array task {id} of {min}..={} (step {step})",
            min + (n - 1) * step
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn detect(vars: &[(&str, &str)], shards: Option<usize>) -> Result<Shard> {
        let map: HashMap<String, String> = vars
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        shard_from_env(&|k| map.get(k).cloned(), shards).map(|d| d.shard)
    }

    fn s(index: usize, count: usize) -> Shard {
        Shard { index, count }
    }

    /// What sbatch sets for task `id` of `--array=min-max:step` (all five variables).
    fn sbatch(id: usize, min: usize, max: usize, step: usize) -> Vec<(&'static str, String)> {
        vec![
            ("SLURM_ARRAY_TASK_ID", id.to_string()),
            ("SLURM_ARRAY_TASK_MIN", min.to_string()),
            ("SLURM_ARRAY_TASK_MAX", max.to_string()),
            ("SLURM_ARRAY_TASK_STEP", step.to_string()),
            (
                "SLURM_ARRAY_TASK_COUNT",
                ((max - min) / step + 1).to_string(),
            ),
        ]
    }

    fn as_refs<'a>(v: &'a [(&'static str, String)]) -> Vec<(&'static str, &'a str)> {
        v.iter().map(|(k, v)| (*k, v.as_str())).collect()
    }

    #[test]
    fn slurm_arrays_from_zero_one_or_anywhere_cover_1_to_n_once() {
        for (min, max, step) in [(0, 2, 1), (1, 3, 1), (5, 9, 1), (0, 18, 2), (1, 1, 1)] {
            let n = (max - min) / step + 1;
            let got: Vec<Shard> = (min..=max)
                .step_by(step)
                .map(|id| detect(&as_refs(&sbatch(id, min, max, step)), None).unwrap())
                .collect();
            let want: Vec<Shard> = (1..=n).map(|i| s(i, n)).collect();
            assert_eq!(got, want, "--array={min}-{max}:{step}");
        }
        // MIN with COUNT only, MAX with COUNT only (first id derived), MIN/MAX only.
        let only = |v: &[(&str, &str)]| detect(v, None).unwrap();
        assert_eq!(
            only(&[
                ("SLURM_ARRAY_TASK_ID", "1"),
                ("SLURM_ARRAY_TASK_MIN", "1"),
                ("SLURM_ARRAY_TASK_COUNT", "3")
            ]),
            s(1, 3)
        );
        assert_eq!(
            only(&[
                ("SLURM_ARRAY_TASK_ID", "1"),
                ("SLURM_ARRAY_TASK_MAX", "2"),
                ("SLURM_ARRAY_TASK_COUNT", "3")
            ]),
            s(2, 3)
        );
        assert_eq!(
            only(&[
                ("SLURM_ARRAY_TASK_ID", "3"),
                ("SLURM_ARRAY_TASK_MIN", "1"),
                ("SLURM_ARRAY_TASK_MAX", "3")
            ]),
            s(3, 3)
        );
        // --shards agreeing is fine, disagreeing is an error.
        assert_eq!(
            detect(&as_refs(&sbatch(0, 0, 2, 1)), Some(3)).unwrap(),
            s(1, 3)
        );
        assert!(detect(&as_refs(&sbatch(0, 0, 2, 1)), Some(4)).is_err());
    }

    #[test]
    fn slurm_lists_with_gaps_and_missing_first_id_are_refused() {
        // --array=1,4,9: MIN 1, MAX 9, COUNT 3.
        let e = detect(
            &[
                ("SLURM_ARRAY_TASK_ID", "4"),
                ("SLURM_ARRAY_TASK_MIN", "1"),
                ("SLURM_ARRAY_TASK_MAX", "9"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ],
            None,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("not a plain range"), "{e}");
        let e = detect(
            &[
                ("SLURM_ARRAY_TASK_ID", "1"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ],
            None,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("SLURM_ARRAY_TASK_MIN"), "{e}");
        assert!(detect(&as_refs(&sbatch(7, 0, 2, 1)), None).is_err());
        assert!(detect(
            &[("SLURM_ARRAY_TASK_ID", "x"), ("SLURM_ARRAY_TASK_MIN", "0")],
            None
        )
        .is_err());
    }

    #[test]
    fn kubernetes_and_aws_are_zero_based_with_the_count_given() {
        for var in ["JOB_COMPLETION_INDEX", "AWS_BATCH_JOB_ARRAY_INDEX"] {
            let got: Vec<Shard> = (0..4)
                .map(|i| detect(&[(var, &i.to_string())], Some(4)).unwrap())
                .collect();
            assert_eq!(got, (1..=4).map(|i| s(i, 4)).collect::<Vec<_>>());
            assert_eq!(
                detect(&[(var, "2"), (SHARDS_VAR, "3")], None).unwrap(),
                s(3, 3)
            );
            let e = detect(&[(var, "0")], None).unwrap_err().to_string();
            assert!(e.contains("--shards") && e.contains(SHARDS_VAR), "{e}");
            assert!(
                detect(&[(var, "3")], Some(3)).is_err(),
                "index past the count"
            );
            assert!(detect(&[(var, "0"), (SHARDS_VAR, "2")], Some(3)).is_err());
        }
    }

    #[test]
    fn nothing_set_names_every_variable_and_two_schedulers_are_ambiguous() {
        let e = detect(&[("HOME", "/root")], Some(3)).unwrap_err();
        assert!(matches!(e, Error::Usage(_)));
        let e = e.to_string();
        for v in INDEX_VARS {
            assert!(e.contains(v), "{e}");
        }
        assert!(
            detect(&[("SLURM_ARRAY_TASK_ID", "")], Some(3)).is_err(),
            "empty is unset"
        );
        let e = detect(
            &[
                ("JOB_COMPLETION_INDEX", "0"),
                ("AWS_BATCH_JOB_ARRAY_INDEX", "0"),
            ],
            Some(2),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("JOB_COMPLETION_INDEX and AWS_BATCH_JOB_ARRAY_INDEX"),
            "{e}"
        );
    }
}
