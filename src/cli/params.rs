//! Parsing and checking option values several commands share: `--resolution`, frame numbers,
//! and the assignment of `--param name=value` to the selected techniques.

use gibench_harness::technique::{Params, TechniqueInfo};
use gibench_harness::{Error, Result};

/// `--resolution WIDTHxHEIGHT` as `[width, height]`.
pub(crate) fn parse_resolution(s: &str) -> Result<[u32; 2]> {
    let bad = || {
        Error::param(
            "resolution",
            format!("expected WIDTHxHEIGHT, e.g. 256x192 (got '{s}')"),
        )
    };
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    Ok([
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    ])
}

/// Splits `--param` values among the selected techniques. A bare `name=value` goes to every
/// technique that declares `name`; it is an error if none does, and an error if a technique
/// would get the same parameter twice (`vpls=8` and `laine.vpls=16`: which one holds would
/// depend on their order).
pub(crate) fn assign_params(techniques: &[&TechniqueInfo], raw: &[String]) -> Result<Vec<Params>> {
    // Per technique: (parameter, value, the `--param` it came from).
    let mut given: Vec<Vec<(String, String, &str)>> = vec![Vec::new(); techniques.len()];
    for p in raw {
        let (key, value) = p.split_once('=').ok_or_else(|| {
            Error::param(p.clone(), "expected name=value or technique.name=value")
        })?;
        let targets: Vec<(usize, &str)> = match key.split_once('.') {
            Some((t, name)) => {
                let i = techniques
                    .iter()
                    .position(|info| info.name == t)
                    .ok_or_else(|| {
                        Error::param(
                            key,
                            format!("technique '{t}' is not among the selected techniques"),
                        )
                    })?;
                vec![(i, name)]
            }
            None => techniques
                .iter()
                .enumerate()
                .filter(|(_, info)| info.has_param(key))
                .map(|(i, _)| (i, key))
                .collect(),
        };
        if targets.is_empty() {
            let known: Vec<String> = techniques
                .iter()
                .map(|t| {
                    let names: Vec<&str> = t.param_specs().map(|s| s.name).collect();
                    format!(
                        "{}: {}",
                        t.name,
                        if names.is_empty() {
                            "none".into()
                        } else {
                            names.join(", ")
                        }
                    )
                })
                .collect();
            return Err(Error::param(
                key,
                format!(
                    "no selected technique has this parameter ({})",
                    known.join("; ")
                ),
            ));
        }
        for (i, name) in targets {
            if let Some((.., first)) = given[i].iter().find(|(n, ..)| n == name) {
                return Err(Error::param(
                    format!("{}.{name}", techniques[i].name),
                    format!("given twice ('{first}' and '{p}'); give each parameter once"),
                ));
            }
            given[i].push((name.to_string(), value.to_string(), p));
        }
    }
    techniques
        .iter()
        .zip(given)
        .map(|(t, g)| {
            let pairs: Vec<(String, String)> = g.into_iter().map(|(n, v, _)| (n, v)).collect();
            t.parse_params(&pairs)
        })
        .collect()
}

/// Checks a frame number or count given as option `option` against the limit every command
/// shares ([`gibench_harness::runner::MAX_FRAMES`]).
pub(crate) fn check_frame_number(option: &str, frame: u32) -> Result<()> {
    let max = gibench_harness::runner::MAX_FRAMES;
    if frame > max {
        return Err(Error::param(
            option,
            format!("{frame} exceeds the limit of {max}"),
        ));
    }
    Ok(())
}
