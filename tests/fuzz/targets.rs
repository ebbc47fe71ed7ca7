//! The fuzz targets: what each reads, from which valid inputs its mutations start, and what it
//! does with an input that parses (the checks and tables that follow parsing in gibench).

use std::path::Path;

use proptest::prelude::*;
use serde_json::Value;

use super::{campaign, json_files, mutate_json, mutation, read_json, repo};
use gibench_harness::measure::results::RunResult;
use gibench_harness::scene::descriptor::SceneDescriptor;

/// Scene descriptors (`--scene FILE.json`): every committed descriptor as a seed; parsed, then
/// validated (what `gibench run` does before loading anything).
#[test]
fn scene_descriptor() {
    let seeds = json_files(&repo().join("scenes"), 64);
    let path = Path::new("fuzzed-scene.json");
    campaign(
        "scene-descriptor",
        mutation(seeds.len()),
        |m| mutate_json(&seeds, m),
        &|bytes| {
            let Ok(text) = std::str::from_utf8(bytes) else {
                return false;
            };
            SceneDescriptor::from_json(path, text).is_ok_and(|d| d.validate(path).is_ok())
        },
    );
}

/// Results files (`report`, `compare`, `export`): the committed baseline's runs as seeds; read
/// as `report` reads them, then every table built from them.
#[test]
fn results_file() {
    let seeds = json_files(&repo().join("results/baseline/r1"), 16);
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("run.json");
    campaign(
        "results-file",
        mutation(seeds.len()),
        |m| mutate_json(&seeds, m),
        &|bytes| {
            std::fs::write(&file, bytes).unwrap();
            let Ok(r) = RunResult::read(&file) else {
                return false;
            };
            use gibench_harness::report;
            let runs = [r.clone(), r];
            let _ = report::stage_table(&runs);
            let _ = report::stage_table_detailed(&runs[0]);
            let _ = report::glance_table(&runs);
            let _ = report::equal_time_table(&runs);
            let _ = report::roofline_table(&runs[0]);
            let _ = report::speedup_table(&runs);
            let _ = report::pareto_line(&runs);
            true
        },
    );
}

/// `reproduce all` manifests, pooled by `gibench merge` (two shards' folders, one fuzzed).
#[test]
fn reproduce_all_manifest() {
    let committed = read_json(&repo().join("results/reproduce-all.json"));
    // Two shards of the committed manifest: the first half of its targets and the rest, each
    // target run (not carried) with its first file, written there.
    let mut targets = committed["targets"].as_array().unwrap().clone();
    for t in &mut targets {
        let t = t.as_object_mut().unwrap();
        t.remove("carried_from");
        t.remove("left_out");
        let first: Vec<Value> = t["files"]
            .as_array()
            .unwrap()
            .iter()
            .take(1)
            .cloned()
            .collect();
        t["files"] = first.into();
    }
    let half = targets.len() / 2;
    let shard = |part: &[Value], i: usize| {
        let mut m = committed.clone();
        m["targets"] = Value::from(part.to_vec());
        m["shard"] = format!("{i}/2").into();
        m["shard_source"] = "--shard".into();
        m["selected"] = targets
            .iter()
            .map(|t| t["name"].clone())
            .collect::<Vec<_>>()
            .into();
        m
    };
    let seeds = vec![shard(&targets[..half], 0), shard(&targets[half..], 1)];
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    for (d, s) in [(&a, &seeds[0]), (&b, &seeds[1])] {
        std::fs::create_dir_all(d).unwrap();
        std::fs::write(d.join("reproduce-all.json"), serde_json::to_vec(s).unwrap()).unwrap();
        for t in s["targets"].as_array().unwrap() {
            for f in t["files"].as_array().unwrap() {
                let f = d.join(f.as_str().unwrap());
                std::fs::create_dir_all(f.parent().unwrap()).unwrap();
                std::fs::write(f, "a target's file").unwrap();
            }
        }
    }
    // The seeds merge: a fuzzed input that does not is refused, not a broken setup.
    gibench_papers::reproduce::all::merge(&[a.clone(), b.clone()], &tmp.path().join("m0"))
        .expect("the seed manifests merge");
    let out = tmp.path().join("merged");
    campaign(
        "reproduce-all-manifest",
        mutation(seeds.len()),
        |m| mutate_json(&seeds, m),
        &|bytes| {
            std::fs::write(a.join("reproduce-all.json"), bytes).unwrap();
            gibench_papers::reproduce::all::merge(&[a.clone(), b.clone()], &out).is_ok()
        },
    );
}

/// Run and sweep shard records (`gibench merge` of `run --shard` folders), read back.
#[test]
fn shard_record() {
    use gibench_papers::shard::{ShardArgs, ShardRecord, RECORD};
    let shard = ShardArgs {
        shard: Some("1/3".into()),
        shard_count: None,
    }
    .resolve_with(&|_| None)
    .unwrap()
    .unwrap();
    let mut record = ShardRecord::new(
        "run",
        &shard,
        vec!["cornell-keller-full".into(), "cornell-laine".into()],
        [
            ("frames", "20"),
            ("resolution", "256x192"),
            ("git_commit", "abc1234"),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect(),
    );
    record.ran = vec![("cornell-laine".into(), "cornell-laine.json".into())];
    let seeds = vec![serde_json::to_value(&record).unwrap()];
    let dir = tempfile::tempdir().unwrap();
    campaign(
        "shard-record",
        mutation(seeds.len()),
        |m| mutate_json(&seeds, m),
        &|bytes| {
            std::fs::write(dir.path().join(RECORD), bytes).unwrap();
            ShardRecord::read(dir.path()).is_ok()
        },
    );
}

/// A command-line value: one of a few shapes the parsers expect, or anything.
fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        "[0-9]{0,12}[xX][0-9]{0,12}",
        "[0-9]{0,20}(\\.[0-9]{0,6})?(ms|s|m|h|us|)",
        "[0-9]{1,3}(m[0-9]{1,3}s)?",
        "-?[0-9]{0,3}/-?[0-9]{0,3}",
        "[a-z-]{0,16}",
        any::<String>(),
    ]
}

/// The command line's value parsers, and every technique's parameters (`--param k=v`), with
/// what follows a parse (the reference component the parameters pick), and the job system's
/// variables a shard reads.
#[test]
fn command_line_values() {
    use gibench_harness::kit::technique::{parse_tiles, TechniqueInfo};
    let techniques = gibench_papers::registry::all();
    let names: Vec<&str> = techniques
        .iter()
        .flat_map(TechniqueInfo::param_specs)
        .map(|s| s.name)
        .collect();
    let strategy = (
        value(),
        prop::collection::vec((0..names.len() + 1, value()), 0..4),
        0..techniques.len(),
        prop::collection::vec(value(), 0..4),
    );
    campaign(
        "command-line",
        strategy,
        |(v, pairs, t, env)| {
            serde_json::to_vec(&serde_json::json!({
                "value": v,
                "technique": t,
                "params": pairs.iter().map(|(k, v)| (names.get(*k).copied().unwrap_or("unknown"), v)).collect::<Vec<_>>(),
                "env": env,
            }))
            .unwrap()
        },
        &|bytes| {
            let Ok(input) = serde_json::from_slice::<Value>(bytes) else {
                return false;
            };
            let v = input["value"].as_str().unwrap_or_default();
            let _ = gibench_papers::params::parse_resolution(v);
            let _ = gibench_papers::params::parse_budget(v);
            let _ = gibench_papers::equal_time::parse_budget(v);
            let _ = parse_tiles(v);
            let _ = gibench_harness::run::config::TimingMode::parse(v);
            let _ = gibench_harness::report::TableFormat::parse("format", v);
            let _ = gibench_harness::kit::ir::atlas::MapKind::parse(v);
            let _ = gibench_harness::cpu::reference::IndirectComponent::parse(v);
            let words: Vec<&str> = v.split(' ').collect();
            let _ = gibench_papers::reproduce::ReproduceArgs::parse_words(&words);
            let t =
                &techniques[input["technique"].as_u64().unwrap_or(0) as usize % techniques.len()];
            let pairs: Vec<(String, String)> =
                serde_json::from_value(input["params"].clone()).unwrap_or_default();
            if let Ok(p) = t.parse_params(&pairs) {
                let _ = (t.reference)(&p);
            }
            let env: Vec<String> = serde_json::from_value(input["env"].clone()).unwrap_or_default();
            let vars = [
                "SLURM_ARRAY_TASK_ID",
                "SLURM_ARRAY_TASK_COUNT",
                "SLURM_ARRAY_TASK_MIN",
                "JOB_COMPLETION_INDEX",
                "GIBENCH_SHARD_COUNT",
                "BUILDKITE_PARALLEL_JOB",
                "BUILDKITE_PARALLEL_JOB_COUNT",
            ];
            let get = |k: &str| {
                let i = vars.iter().position(|x| *x == k)?;
                env.get(i).cloned()
            };
            let args = gibench_papers::shard::ShardArgs {
                shard: env.first().cloned(),
                shard_count: env.get(1).cloned(),
            };
            let _ = gibench_papers::shard::ShardArgs::default().resolve_with(&get);
            args.resolve_with(&get).is_ok()
        },
    );
}

/// glTF binaries (`.glb`, the scenes' meshes): the shared Cornell box and punctual-lights
/// scenes as seeds, their JSON chunk mutated (sometimes their binary chunk too) and repacked;
/// loaded as a scene's glTF is.
#[test]
fn gltf_binary() {
    let scenes = repo().join("../shared/scenes");
    let seeds: Vec<(Value, Vec<u8>)> = ["cornell.glb", "lights-punctual-cubes.glb"]
        .iter()
        .map(|f| {
            let path = scenes.join(f);
            let b = std::fs::read(&path)
                .unwrap_or_else(|e| panic!("{}: {e} (the shared scenes)", path.display()));
            unpack(&b)
        })
        .collect();
    let jsons: Vec<Value> = seeds.iter().map(|s| s.0.clone()).collect();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("fuzzed.glb");
    campaign(
        "gltf-binary",
        (
            mutation(seeds.len()),
            prop::collection::vec((any::<u32>(), any::<u8>()), 0..3),
        ),
        |(m, flips)| {
            let json = mutate_json(&jsons, m);
            let mut bin = seeds[m.seed % seeds.len()].1.clone();
            for (at, x) in flips {
                if !bin.is_empty() {
                    let i = *at as usize % bin.len();
                    bin[i] ^= x | 1;
                }
            }
            pack(&json, &bin)
        },
        &|bytes| {
            std::fs::write(&file, bytes).unwrap();
            gibench_harness::scene::gltf_load::load_gltf(&file, 0).is_ok()
        },
    );
}

/// A GLB's JSON chunk (parsed) and binary chunk.
fn unpack(b: &[u8]) -> (Value, Vec<u8>) {
    let u32_at = |i: usize| u32::from_le_bytes(b[i..i + 4].try_into().unwrap()) as usize;
    let json_len = u32_at(12);
    let json = serde_json::from_slice(&b[20..20 + json_len]).unwrap();
    let rest = 20 + json_len;
    let bin = if rest + 8 <= b.len() {
        b[rest + 8..rest + 8 + u32_at(rest)].to_vec()
    } else {
        Vec::new()
    };
    (json, bin)
}

/// A GLB of `json` (padded with spaces) and `bin` (padded with zeros).
fn pack(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let pad = |n: usize| n.div_ceil(4) * 4;
    let (jl, bl) = (pad(json.len()), pad(bin.len()));
    let total = 12 + 8 + jl + if bin.is_empty() { 0 } else { 8 + bl };
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(jl as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(json);
    out.resize(20 + jl, b' ');
    if !bin.is_empty() {
        out.extend_from_slice(&(bl as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(bin);
        out.resize(total, 0);
    }
    out
}
