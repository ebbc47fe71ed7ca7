//! Shader modules by name. A WGSL source names the shared modules it needs with `#import NAME`
//! lines (each alone on its line, anywhere in the text); [`compose`] replaces them with the
//! named modules, each included once however many sources and modules import it, a module's
//! own imports resolved the same way, and the prelude [`PRELUDE`] (`View`, `Light`, helpers)
//! always included. WGSL's module-scope declarations may come in any order, so a module needs
//! no place before its users: only its presence, once. Bindings whose group or binding index a
//! pass chooses stay Rust-generated text beside an import (`VplStore::wgsl`,
//! `ShadowAtlas::wgsl`, `DirectLight::wgsl`).
//!
//! An unknown import is a bug of ours, not bad input: [`compose`] says which, and the test
//! over every shader of the repository (`every_shader_resolves_and_defines_each_name_once`)
//! finds it before any run does.

use std::collections::HashSet;

/// One shared WGSL module: its name (`gibench::vpl_store`) and source.
#[derive(Clone, Copy, Debug)]
pub struct WgslModule {
    pub name: &'static str,
    pub source: &'static str,
}

/// The module every shader gets.
pub const PRELUDE: &str = "gibench::common";

/// The kit's shared modules.
pub const MODULES: &[WgslModule] = &[
    WgslModule {
        name: "gibench::common",
        source: include_str!("passes/shaders/common.wgsl"),
    },
    WgslModule {
        name: "gibench::mesh",
        source: include_str!("passes/shaders/mesh.wgsl"),
    },
    WgslModule {
        name: "gibench::direct_light",
        source: include_str!("passes/shaders/direct_light.wgsl"),
    },
    WgslModule {
        name: "gibench::vpl_store",
        source: include_str!("ir/shaders/vpl_store.wgsl"),
    },
    WgslModule {
        name: "gibench::prepared_vpl",
        source: include_str!("ir/shaders/prepared_vpl.wgsl"),
    },
    WgslModule {
        name: "gibench::atlas_lookup",
        source: include_str!("ir/shaders/atlas_lookup.wgsl"),
    },
    WgslModule {
        name: "gibench::interleave",
        source: include_str!("ir/shaders/interleave.wgsl"),
    },
    WgslModule {
        name: "gibench::pullpush",
        source: include_str!("ir/shaders/pullpush.wgsl"),
    },
];

const IMPORT: &str = "#import ";

/// The names `source` imports, in order.
pub fn imports(source: &str) -> impl Iterator<Item = &str> {
    source
        .lines()
        .filter_map(|l| l.trim().strip_prefix(IMPORT))
        .map(str::trim)
}

/// `source` with the prelude and every import resolved (see the module docs); an unknown
/// import is an error naming it and the module that asked for it.
pub fn compose(source: &str) -> Result<String, String> {
    let mut out = String::new();
    let mut included = HashSet::new();
    include(PRELUDE, "the prelude", &mut included, &mut out)?;
    append(source, "the shader", &mut included, &mut out)?;
    Ok(out)
}

/// Appends `source` to `out`, each of its import lines replaced by the module (when not yet
/// included).
fn append(
    source: &str,
    from: &str,
    included: &mut HashSet<&'static str>,
    out: &mut String,
) -> Result<(), String> {
    for line in source.lines() {
        match line.trim().strip_prefix(IMPORT) {
            Some(name) => include(name.trim(), from, included, out)?,
            None => {
                out.push_str(line);
                out.push('\n');
            }
        }
    }
    Ok(())
}

fn include(
    name: &str,
    from: &str,
    included: &mut HashSet<&'static str>,
    out: &mut String,
) -> Result<(), String> {
    let Some(m) = MODULES.iter().find(|m| m.name == name) else {
        return Err(format!(
            "WGSL: {from} imports '{name}', which is no module (known: {})",
            MODULES
                .iter()
                .map(|m| m.name)
                .collect::<Vec<_>>()
                .join(", ")
        ));
    };
    if included.insert(m.name) {
        out.push_str(&format!("// ---- {} ----\n", m.name));
        append(m.source, m.name, included, out)?;
    }
    Ok(())
}

/// The module-scope names `composed` declares (`fn`, `struct`, `const`, `override`, `alias`,
/// `var`), each as often as declared: a name twice is a definition included twice.
pub fn declared_names(composed: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut depth = 0i32;
    for line in composed.lines() {
        let code = line.split("//").next().unwrap_or("");
        if depth == 0 {
            let t = strip_attributes(code.trim_start());
            for kw in ["fn ", "struct ", "const ", "override ", "alias ", "var "] {
                if let Some(rest) = t.strip_prefix(kw) {
                    names.push(name_of(rest.trim_start()));
                }
            }
            // `var<storage, read> name: T`.
            if let Some((_, rest)) = t.strip_prefix("var<").and_then(|r| r.split_once('>')) {
                names.push(name_of(rest.trim_start()));
            }
        }
        depth += code.matches('{').count() as i32 - code.matches('}').count() as i32;
    }
    names.retain(|n| !n.is_empty());
    names
}

/// `t` without its leading attributes (`@group(0) @binding(1) `, `@compute @workgroup_size(8, 8) `).
fn strip_attributes(mut t: &str) -> &str {
    while let Some(rest) = t.strip_prefix('@') {
        let name_len = rest
            .find(|c: char| !(c.is_alphanumeric() || c == '_'))
            .unwrap_or(rest.len());
        let mut rest = rest[name_len..].trim_start();
        if let Some(args) = rest.strip_prefix('(') {
            rest = args.split_once(')').map_or("", |(_, r)| r);
        }
        t = rest.trim_start();
    }
    t
}

fn name_of(s: &str) -> String {
    s.chars()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn imports_resolve_once_and_unknown_ones_are_named() {
        let a = compose("#import gibench::vpl_store\n#import gibench::atlas_lookup\nfn main() {}")
            .unwrap();
        // atlas_lookup imports vpl_store too: included once.
        assert_eq!(a.matches("// ---- gibench::vpl_store ----").count(), 1);
        assert_eq!(a.matches("// ---- gibench::common ----").count(), 1);
        assert!(a.ends_with("fn main() {}\n"));
        let e = compose("#import gibench::teapot\n").unwrap_err();
        assert!(
            e.contains("'gibench::teapot'") && e.contains("the shader"),
            "{e}"
        );
    }

    /// Every `.wgsl` file of the harness and the techniques.
    fn shader_files() -> Vec<std::path::PathBuf> {
        fn walk(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
            for e in std::fs::read_dir(dir).into_iter().flatten().flatten() {
                let p = e.path();
                if p.is_dir() {
                    walk(&p, out);
                } else if p.extension().is_some_and(|x| x == "wgsl") {
                    out.push(p);
                }
            }
        }
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut files = Vec::new();
        walk(&root.join("src"), &mut files);
        walk(&root.join("../techniques"), &mut files);
        files
    }

    /// Catches: an import of a module that does not exist, and a definition included twice
    /// (a module pasted into a shader that also imports it, or two modules defining one name):
    /// every shader of the repository composed alone declares each name once.
    #[test]
    fn every_shader_resolves_and_defines_each_name_once() {
        let files = shader_files();
        assert!(files.len() >= 30, "{} shaders found", files.len());
        let mut wrong = Vec::new();
        for f in &files {
            let mut source = std::fs::read_to_string(f).unwrap();
            // A module is composed as its importers get it.
            if let Some(m) = MODULES.iter().find(|m| m.source == source) {
                source = format!("#import {}", m.name);
            }
            match compose(&source) {
                Err(e) => wrong.push(format!("{}: {e}", f.display())),
                Ok(composed) => {
                    let mut names = declared_names(&composed);
                    names.sort();
                    let twice: Vec<&String> = names
                        .windows(2)
                        .filter(|w| w[0] == w[1])
                        .map(|w| &w[0])
                        .collect();
                    if !twice.is_empty() {
                        wrong.push(format!("{}: declared twice: {twice:?}", f.display()));
                    }
                }
            }
        }
        for (i, m) in MODULES.iter().enumerate() {
            if MODULES[..i].iter().any(|o| o.name == m.name) {
                wrong.push(format!("module {} registered twice", m.name));
            }
        }
        assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    }

    #[test]
    fn declared_names_finds_module_scope_declarations() {
        let names = declared_names(
            "struct S { a: f32 }\nconst K: u32 = 1u;\n@group(0) @binding(1) var<storage, read> buf: S;\n\
             var<private> p: f32;\nfn f(x: f32) -> f32 {\n    let y = x;\n    var z = y;\n    return z;\n}\n\
             @compute @workgroup_size(8, 8) fn main() {}\n@group(1) @binding(0) var tex: texture_2d<f32>;\n",
        );
        assert_eq!(names, ["S", "K", "buf", "p", "f", "main", "tex"]);
    }
}
