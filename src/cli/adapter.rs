//! `gibench adapter`: the adapter runs would use (the same choice as `run`'s `--backend` and
//! `--adapter`), printed; with `--require-gpu` a CPU rasteriser is refused by name, so that a
//! GPU slot (`scripts/gpu-run.sh`) never spends its time timing the wrong device.

use clap::Args;
use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::{Error, Result};

use gibench_papers::options::GpuArgs;

#[derive(Args)]
pub(crate) struct AdapterArgs {
    #[command(flatten)]
    gpu: GpuArgs,
    /// Fail when the adapter is a CPU rasteriser (llvmpipe, lavapipe, SwiftShader, WARP), not a
    /// GPU.
    #[arg(long)]
    require_gpu: bool,
    /// Print only the adapter's name as a file-name slug (`nvidia-h100-80gb-hbm3`), as
    /// `results/gpu-<slug>/` uses it.
    #[arg(long)]
    slug: bool,
}

pub(crate) fn exec(args: &AdapterArgs) -> Result<()> {
    let gpu = GpuContext::new(&GpuOptions {
        backend: args.gpu.backend.clone(),
        adapter: args.gpu.adapter.clone(),
        gpu_timeout: args.gpu.gpu_timeout,
        limits: None,
    })?;
    let i = &gpu.info;
    if args.require_gpu && i.is_software() {
        return Err(Error::Invalid(format!(
            "--require-gpu: the adapter is '{}' ({}, device type {}, driver {}), a CPU \
             rasteriser, not a GPU; name a GPU with --backend or --adapter, or install its \
             driver's Vulkan or EGL loader",
            i.adapter, i.backend, i.device_type, i.driver
        )));
    }
    if args.slug {
        println!("{}", slug(&i.adapter));
    } else {
        let driver = [i.driver.as_str(), i.driver_info.as_str()]
            .iter()
            .filter(|s| !s.is_empty())
            .copied()
            .collect::<Vec<_>>()
            .join(" ");
        println!(
            "{} ({}, device type {}, driver {driver}, timestamp queries {})",
            i.adapter,
            i.backend,
            i.device_type,
            if i.timestamp_queries { "yes" } else { "no" }
        );
    }
    Ok(())
}

/// Lowercase letters and digits, every other run of characters one `-`, none at the ends.
fn slug(name: &str) -> String {
    let mut s = String::new();
    for c in name.chars() {
        if c.is_ascii_alphanumeric() {
            s.push(c.to_ascii_lowercase());
        } else if !s.ends_with('-') {
            s.push('-');
        }
    }
    let s = s.trim_matches('-').to_string();
    if s.is_empty() {
        "unknown".into()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn slugs_are_lowercase_words() {
        assert_eq!(
            super::slug("NVIDIA H100 80GB HBM3"),
            "nvidia-h100-80gb-hbm3"
        );
        assert_eq!(
            super::slug("llvmpipe (LLVM 15.0.6, 256 bits)"),
            "llvmpipe-llvm-15-0-6-256-bits"
        );
        assert_eq!(super::slug("(()"), "unknown");
    }
}
