//! `gibench list`: the built-in scenes and the registered techniques with their parameters
//! and defaults.

use gibench_harness::scene::{descriptor, SceneDescriptor};
use gibench_harness::Result;

use crate::registry;

/// `gibench list`: prints the scenes and techniques.
pub(crate) fn exec() -> Result<()> {
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
        println!("  {:<16} {}", t.name, t.description);
        println!(
            "      compared with the {} reference by default; conformance: relative L1 error <= {}, mean ratio {}-{}",
            t.default_reference().name(),
            t.conformance.max_relative_l1,
            t.conformance.mean_ratio.0,
            t.conformance.mean_ratio.1
        );
        if t.param_specs().next().is_none() {
            println!("      (no parameters)");
        }
        for p in t.param_specs() {
            println!("      {:<14} default {:<8} {}", p.name, p.default, p.doc);
        }
    }
    Ok(())
}
