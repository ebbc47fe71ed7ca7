//! The pass builder ([`Bindings`]): one declaration gives a bind-group layout and the group that
//! matches it.

use gibench_harness::kit::passes::Bindings;
use gibench_harness::wgpu;
use gibench_test_support::gpus;

/// Bindings are numbered in the order declared (from `first_binding` where given), each with
/// the access its call states, and the layout and the group built from them are valid together.
/// Catches a numbering that restarts at 0 after `first_binding`, a written buffer declared
/// read-only (the shader's `read_write` then fails pipeline creation), and group entries whose
/// numbers differ from the layout's.
#[test]
fn bindings_are_numbered_in_order_with_the_declared_access() {
    for (backend, gpu) in gpus("bindings_are_numbered_in_order_with_the_declared_access") {
        let buffer = |label| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 64,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            })
        };
        let (a, b, c) = (buffer("a"), buffer("b"), buffer("c"));
        let declared = Bindings::new("test", wgpu::ShaderStages::COMPUTE)
            .first_binding(4)
            .read(&a)
            .write(&b)
            .params(&c);
        let access: Vec<(u32, Option<bool>)> = (declared.entries().iter())
            .map(|e| match e.ty {
                wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only },
                    ..
                } => (e.binding, Some(read_only)),
                _ => (e.binding, None),
            })
            .collect();
        assert_eq!(
            access,
            [(4, Some(true)), (5, Some(false)), (6, Some(true))],
            "{backend}"
        );
        let bound = declared.build(&gpu.device);
        let shader = "@group(0) @binding(4) var<storage, read> a: array<u32>;
            @group(0) @binding(5) var<storage, read_write> b: array<u32>;
            @group(0) @binding(6) var<storage, read> c: array<u32>;
            @compute @workgroup_size(1) fn main() { b[0] = a[0] + c[0]; }";
        let pipeline = gibench_harness::kit::passes::compute_pipeline(
            &gpu.device,
            "bindings test",
            shader,
            &[&bound.layout],
            "main",
        );
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bound.group, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        gpu.queue.submit([encoder.finish()]);
        gpu.check_errors()
            .unwrap_or_else(|e| panic!("{backend}: the declared group is not valid: {e}"));
    }
}
