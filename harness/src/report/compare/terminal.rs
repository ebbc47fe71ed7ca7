//! `gibench compare`'s terminal output: one block per run, its label once, then one line per
//! stage with both medians, the ratios, p and the verdict on that line (the general table's
//! folding repeated a long label in every block and put a stage's verdict far below its ratio).

use super::markdown::short_labels;
use super::{compare_table, CompareRow, Settings};

/// The comparison as the terminal shows it (see the module docs): the title, a block per run,
/// then the table's notes and `notes`.
pub fn compare_terminal(rows: &[CompareRow], settings: &Settings, notes: &[String]) -> String {
    let table = compare_table(rows, settings);
    let labels = short_labels(rows);
    let stage_width = (rows.iter())
        .map(|r| r.stage.chars().count())
        .chain(["stage".len()])
        .max()
        .unwrap_or(5);
    let ratio = |r: Option<f64>| r.map_or("–".to_string(), |r| format!("{r:.3}"));
    let mut out = format!("{}\n", table.title);
    let mut run: Option<&str> = None;
    for r in rows {
        if run != Some(r.run.as_str()) {
            run = Some(r.run.as_str());
            let label = labels.get(r.run.as_str()).unwrap_or(&r.run);
            out.push_str(&format!(
                "\n{label}\n  {:<stage_width$} {:>10} {:>10} {:>10} {:>10} {:>15}  verdict\n",
                "stage", "base ms", "current ms", "ratio", "calibrated", "p"
            ));
        }
        let p = r.p_value.map_or("–".to_string(), |p| {
            format!("{p:.4}{}", if r.p_exact { "" } else { " (normal)" })
        });
        out.push_str(&format!(
            "  {:<stage_width$} {:>10.3} {:>10.3} {:>10} {:>10} {:>15}  {}\n",
            r.stage,
            r.base_ms,
            r.current_ms,
            ratio(r.ratio_raw),
            ratio(r.ratio_calibrated),
            p,
            r.verdict.name()
        ));
    }
    for note in table.notes.iter().chain(notes) {
        out.push_str(&format!("\n{note}"));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::{CompareRow, Settings, Statistic, Verdict};

    fn row(run: &str, stage: &str, verdict: Verdict) -> CompareRow {
        CompareRow {
            run: run.into(),
            stage: stage.into(),
            base_ms: 1.0,
            current_ms: 1.3,
            statistic: Statistic::Min,
            ratio_raw: Some(1.3),
            ratio: Some(1.3),
            ratio_calibrated: Some(1.29),
            calibrated: false,
            p_value: Some(0.0079),
            p_exact: true,
            verdict,
            repeats: [5, 5],
            cpu_ms: None,
        }
    }

    /// Catches the general table's folding: a run's label repeated in every block of columns and
    /// a stage's verdict printed far below its ratio. Here the label comes once per run and each
    /// stage's line carries its ratio, p and verdict.
    #[test]
    fn one_line_per_stage_with_its_verdict_and_the_label_once_per_run() {
        let long = "cornell/laine/128x96 (clamp=10, depth-bits=16, recalc-max=8, recalc-min=4, tiles=4x4, vpl-map=paraboloid, vpl-map-size=128, vpls=64)";
        let rows = [
            row(long, "accumulate", Verdict::Slower),
            row(long, "filter", Verdict::Unchanged),
            row("cornell/ism/128x96", "pull-push", Verdict::Faster),
        ];
        let settings = Settings::new(0.15, 0.05, false, Statistic::Min).unwrap();
        let out = super::compare_terminal(&rows, &settings, &["a note".into()]);
        assert_eq!(out.matches("cornell/laine/128x96").count(), 1, "{out}");
        for (stage, verdict) in [
            ("accumulate", "slower"),
            ("filter", "unchanged"),
            ("pull-push", "faster"),
        ] {
            let line = out
                .lines()
                .find(|l| l.trim_start().starts_with(stage))
                .unwrap();
            assert!(
                line.contains("1.300") && line.contains("0.0079") && line.ends_with(verdict),
                "{line}"
            );
        }
        assert!(out.ends_with("a note"), "{out}");
    }
}
