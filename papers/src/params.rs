//! Parsing and checking option values several commands share: `--resolution`, frame numbers,
//! and the assignment of `--param name=value` to the selected techniques.

use gibench_harness::kit::technique::{Params, TechniqueInfo};
use gibench_harness::{Error, Result};

/// `--resolution WIDTHxHEIGHT` as `[width, height]`.
pub fn parse_resolution(s: &str) -> Result<[u32; 2]> {
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
pub fn assign_params(techniques: &[&TechniqueInfo], raw: &[String]) -> Result<Vec<Params>> {
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
/// shares ([`gibench_harness::run::runner::MAX_FRAMES`]).
pub fn check_frame_number(option: &str, frame: u32) -> Result<()> {
    let max = gibench_harness::run::runner::MAX_FRAMES;
    if frame > max {
        return Err(Error::param(
            option,
            format!("{frame} exceeds the limit of {max}"),
        ));
    }
    Ok(())
}

/// A time budget such as `90s`, `2m`, `9m`, `1m30s` or `1h`: numbers each followed by `h`, `m`
/// or `s`, more than zero in all (the `--budget` value parser: clap's error names the option).
pub fn parse_budget(s: &str) -> std::result::Result<std::time::Duration, String> {
    let expected = "expected a duration such as 90s, 2m, 9m or 1m30s (numbers with h, m or s)";
    let mut total = 0.0f64;
    let mut number = String::new();
    for c in s.trim().chars() {
        match c {
            '0'..='9' | '.' => number.push(c),
            'h' | 'm' | 's' if !number.is_empty() => {
                let n: f64 = number
                    .parse()
                    .map_err(|_| format!("{expected}; got '{s}'"))?;
                total += n * match c {
                    'h' => 3600.0,
                    'm' => 60.0,
                    _ => 1.0,
                };
                number.clear();
            }
            _ => return Err(format!("{expected}; got '{s}'")),
        }
    }
    if !(number.is_empty() && total > 0.0 && total.is_finite()) {
        return Err(format!("{expected}, more than zero; got '{s}'"));
    }
    // Past what a Duration holds (about 5.8e11 years): refused, not a panic (found by fuzzing).
    std::time::Duration::try_from_secs_f64(total)
        .map_err(|_| format!("{expected}; got '{s}', too long to count"))
}

#[cfg(test)]
mod budget_tests {
    use super::parse_budget;

    /// Catches: a unit misread (minutes taken for seconds), a bare number or garbage accepted.
    #[test]
    fn budgets_parse_and_bad_ones_are_refused() {
        for (s, secs) in [
            ("90s", 90.0),
            ("2m", 120.0),
            ("9m", 540.0),
            ("1m30s", 90.0),
            ("1h", 3600.0),
            ("1.5m", 90.0),
        ] {
            assert_eq!(parse_budget(s).unwrap().as_secs_f64(), secs, "{s}");
        }
        for s in [
            "",
            "9",
            "m",
            "0s",
            "9x",
            "-1m",
            "1m30",
            "1..2s",
            "10000000000000000h",
        ] {
            let e = parse_budget(s).expect_err(s);
            assert!(e.contains("90s, 2m"), "{s}: {e}");
        }
    }
}
