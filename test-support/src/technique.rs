//! A registered technique run through the harness: parameters from pairs, a few frames
//! rendered as `gibench run` renders them, and what the run left (its irradiance, stages and
//! counters).

use std::collections::BTreeMap;

use gibench_harness::glam::Vec3;
use gibench_harness::gpu::profiler::{ProfileMode, Profiler};
use gibench_harness::kit::technique::{Params, TechniqueInfo};
use gibench_harness::run::runner::{Harness, RunConfig};
use gibench_harness::Result;

/// `-p name=value` pairs as the registry's parser takes them.
pub fn kv(pairs: &[(&str, &str)]) -> Vec<(String, String)> {
    pairs
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

/// What [`Rendered::run`] left.
#[derive(Clone, Debug)]
pub struct Rendered {
    /// The technique's output after the last frame, row by row.
    pub indirect: Vec<Vec3>,
    /// The stages the frames recorded, in order of first use (the harness's and the
    /// technique's).
    pub stages: Vec<String>,
    /// Each counter's mean over the frames.
    pub counters: BTreeMap<String, f64>,
}

impl Rendered {
    /// Prepares and builds `info` with `pairs` on `harness` (made for `config`) and renders
    /// frames `config.first_frame..` + `frames`, every one measured, stage by stage.
    pub fn run(
        harness: &Harness,
        info: &TechniqueInfo,
        pairs: &[(&str, &str)],
        config: &RunConfig,
        frames: u32,
    ) -> Result<Rendered> {
        let params: Params = info.parse_params(&kv(pairs))?;
        let prepared = harness.prepare(info, &params, config)?;
        let (mut technique, compose) = harness.build(info, &params, config, &prepared)?;
        let gpu = harness.gpu;
        let mut profiler = Profiler::new(gpu, ProfileMode::Stages);
        for f in 0..frames {
            let frame = harness.clock.frame(config.first_frame + f);
            harness.render_frame(technique.as_mut(), &compose, &mut profiler, &frame, true)?;
        }
        profiler.finish(gpu)?;
        let counters = profiler
            .counter_results()
            .into_iter()
            .map(|(name, stats)| (name, stats.mean))
            .collect();
        Ok(Rendered {
            indirect: crate::read_rgb(gpu, technique.output().texture()),
            stages: profiler
                .stage_results()
                .into_iter()
                .map(|s| s.name)
                .collect(),
            counters,
        })
    }
}
