//! `gibench list`: the built-in scenes and the registered techniques with their parameters
//! and defaults; `--markdown` prints, from the registry's declarations, the techniques' table
//! that the README holds, their parameter table that docs/running.md holds and their stage
//! table that docs/techniques.md holds (a test checks that each matches).

use clap::Args;
use gibench_harness::kit::technique::{Converged, KnownBias, ParamKind, ParamSpec, TechniqueInfo};
use gibench_harness::measure::results::StageKind;
use gibench_harness::scene::{descriptor, SceneDescriptor};
use gibench_harness::Result;

use gibench_papers::registry;

#[derive(Args)]
pub(crate) struct ListArgs {
    /// Print the techniques (the README's table), their parameters (docs/running.md's) and
    /// their stages and conformance bounds (docs/techniques.md's) as Markdown tables, a blank
    /// line between them.
    #[arg(long)]
    markdown: bool,
}

/// `gibench list`: prints the scenes and techniques.
pub(crate) fn exec(args: &ListArgs) -> Result<()> {
    if args.markdown {
        print!(
            "{}\n{}\n{}",
            technique_table(),
            parameter_table(),
            stage_table()
        );
        return Ok(());
    }
    println!("Scenes (built-in descriptors; any descriptor JSON path also works):");
    for name in descriptor::builtin_names() {
        let d = SceneDescriptor::resolve(name)?;
        let mesh = d
            .mesh
            .file
            .clone()
            .or(d.mesh.generated.clone().map(|g| format!("generated {g}")))
            .unwrap_or_default();
        println!(
            "  {name:<16} {mesh:<28} {:?} light. {}",
            d.light.kind, d.description
        );
    }
    println!("\nTechniques:");
    for t in registry::all() {
        let stages = stage_list(t);
        println!("  {:<16} {}", t.name, t.description);
        println!(
            "      compared with the {} reference by default; known bias at the defaults (mean ratio / relative L1, held within x{} / +{}): {}",
            t.default_reference().name(),
            KnownBias::FACTOR,
            KnownBias::L1_SLACK,
            known_bias(t.conformance.defaults)
        );
        println!(
            "      converged at {} (held within x{} / +{}): {}",
            converged_setting(t),
            Converged::FACTOR,
            Converged::L1_SLACK,
            known_bias(t.conformance.converged.boxes)
        );
        println!("      stages: {stages}");
        match t.knob {
            Some(k) => println!(
                "      quality knob (run --equal-time): {}, its declared range ({})",
                k.param, k.why
            ),
            None => println!("      quality knob (run --equal-time): none"),
        }
        if t.param_specs().next().is_none() {
            println!("      (no parameters)");
        }
        for p in t.param_specs() {
            println!("      {:<14} default {:<8} {}", p.name, p.default, p.doc);
        }
    }
    Ok(())
}

/// The parameters of every registered technique as one Markdown table: a row per declaration
/// (a parameter the kit declares once and several techniques take is one row naming them all),
/// in the registry's order, with its default, its values and its doc.
fn parameter_table() -> String {
    let mut rows: Vec<(&'static ParamSpec, Vec<&'static str>)> = Vec::new();
    for t in registry::all() {
        for p in t.param_specs() {
            let same =
                |q: &&ParamSpec| q.name == p.name && q.default == p.default && q.doc == p.doc;
            match rows.iter_mut().find(|(q, _)| same(q)) {
                Some((_, names)) => names.push(t.name),
                None => rows.push((p, vec![t.name])),
            }
        }
    }
    let mut out = String::from(
        "| parameter | techniques | default | values | meaning |\n|---|---|---|---|---|\n",
    );
    for (p, names) in rows {
        let values = match p.kind {
            ParamKind::Int { min, max } => format!("{min}–{max}"),
            ParamKind::Float { min, max } => format!("{min}–{max}"),
            ParamKind::Bool => "true, false".into(),
            ParamKind::Tiles => "NxM, 1–64 each".into(),
            ParamKind::Choice(words) => words.join(", "),
        };
        out.push_str(&format!(
            "| `{}` | {} | {} | {} | {} |\n",
            p.name,
            names.join(", "),
            p.default,
            values,
            p.doc.replace('|', "\\|")
        ));
    }
    out
}

/// The registered techniques as the README's Markdown table: each name linking its section of
/// docs/techniques.md, its paper and what it is.
fn technique_table() -> String {
    let mut out = String::from("| technique | paper | what it is |\n|---|---|---|\n");
    for t in registry::all() {
        out.push_str(&format!(
            "| [`{0}`](docs/techniques.md#{0}) | {1} | {2} |\n",
            t.name, t.paper, t.summary
        ));
    }
    out
}

/// A technique's own stages in order, the CPU ones marked (the harness's shared stages, the
/// G-buffer and the direct light, are every technique's and not listed).
fn stage_list(t: &TechniqueInfo) -> String {
    let stages: Vec<String> = t
        .stages()
        .map(|s| match s.kind {
            StageKind::Gpu => s.name.to_string(),
            StageKind::Cpu => format!("{} (CPU)", s.name),
        })
        .collect();
    if stages.is_empty() {
        "none of its own".to_string()
    } else {
        stages.join(", ")
    }
}

/// The registered techniques' stages and conformance bounds as docs/techniques.md's table: what
/// each records per frame and what the conformance test holds it to against its reference.
fn stage_table() -> String {
    let mut out = String::from(
        "| technique | its stages (CPU ones marked) | compared with | known bias at the defaults (mean ratio / relative L1) | converged setting: its residual |\n\
         |---|---|---|---|---|\n",
    );
    for t in registry::all() {
        out.push_str(&format!(
            "| `{}` | {} | the {} reference | {} | {}: {} |\n",
            t.name,
            stage_list(t),
            t.default_reference().name(),
            known_bias(t.conformance.defaults),
            converged_setting(t),
            known_bias(t.conformance.converged.boxes)
        ));
    }
    out
}

/// The technique's converged setting (`Converged::params`) and why, or "its defaults".
fn converged_setting(t: &TechniqueInfo) -> String {
    let c = &t.conformance.converged;
    if c.params.is_empty() {
        format!("its defaults ({})", c.why)
    } else {
        format!("`{}` ({})", c.params.join(" "), c.why)
    }
}

/// Known biases per scene (`KnownBias`): `scene mean/L1`, comma-separated.
fn known_bias(entries: &[KnownBias]) -> String {
    entries
        .iter()
        .map(|k| format!("{} {}/{}", k.scene, k.mean_ratio, k.relative_l1))
        .collect::<Vec<_>>()
        .join(", ")
}
