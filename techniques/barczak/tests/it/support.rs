//! A test room for the visibility database and the light maps: six patches, a table, a box
//! mover (object 7) and a sphere mover (object 8), and light samples on its surfaces.

#![allow(dead_code)]

use gibench_barczak::database::{Receiver, ReceiverShape, VisibilityDatabase};
use gibench_barczak::visibility::{Blocker, PatchTree, PointLight, Shape};
use gibench_harness::gpu::GpuContext;
use gibench_harness::run::runner::Harness;
use gibench_harness::scene::Scene;
use glam::Vec3;

/// A 6 × 3 × 6 room: floor (split three times), walls and ceiling (split once), a table top
/// (both a receiver and a blocker), a box mover (six faces, each a receiver and a blocker)
/// and a sphere mover (a complex object: its bounding sphere).
pub fn room() -> (Vec<Receiver>, Vec<Blocker>) {
    let mut receivers = Vec::new();
    let mut blockers = Vec::new();
    let mut add = |object: u32, c: [Vec3; 4], n: Vec3, levels: u32, blocks: bool| {
        receivers.push(Receiver {
            object,
            shape: ReceiverShape::Patch(PatchTree::new(object, c, n, levels)),
        });
        if blocks {
            blockers.push(Blocker {
                object,
                shape: Shape::Polygon(c.to_vec()),
            });
        }
    };
    let v = Vec3::new;
    let (w, h) = (6.0, 3.0);
    add(
        0,
        [v(0., 0., 0.), v(0., 0., w), v(w, 0., w), v(w, 0., 0.)],
        Vec3::Y,
        3,
        false,
    );
    add(
        1,
        [v(0., h, 0.), v(w, h, 0.), v(w, h, w), v(0., h, w)],
        Vec3::NEG_Y,
        1,
        false,
    );
    add(
        2,
        [v(0., 0., 0.), v(w, 0., 0.), v(w, h, 0.), v(0., h, 0.)],
        Vec3::Z,
        1,
        true,
    );
    add(
        3,
        [v(0., 0., w), v(0., h, w), v(w, h, w), v(w, 0., w)],
        Vec3::NEG_Z,
        1,
        true,
    );
    add(
        4,
        [v(0., 0., 0.), v(0., h, 0.), v(0., h, w), v(0., 0., w)],
        Vec3::X,
        1,
        true,
    );
    add(
        5,
        [v(w, 0., 0.), v(w, 0., w), v(w, h, w), v(w, h, 0.)],
        Vec3::NEG_X,
        1,
        true,
    );
    // Table top at 1 m, both sides.
    let top = [
        v(2., 1., 2.),
        v(2., 1., 3.5),
        v(3.5, 1., 3.5),
        v(3.5, 1., 2.),
    ];
    add(6, top, Vec3::Y, 1, true);
    let mut under = top;
    under.reverse();
    add(6, under, Vec3::NEG_Y, 1, false);
    // The box mover, object 7: 0.6 m cube at (1, 0.3..0.9, 1).
    let cube = |x: f32, y: f32, z: f32| v(0.7 + 0.6 * x, 0.3 + 0.6 * y, 0.7 + 0.6 * z);
    let faces = [
        (
            [(0., 0., 0.), (1., 0., 0.), (1., 0., 1.), (0., 0., 1.)],
            Vec3::NEG_Y,
        ),
        (
            [(0., 1., 0.), (0., 1., 1.), (1., 1., 1.), (1., 1., 0.)],
            Vec3::Y,
        ),
        (
            [(0., 0., 0.), (0., 0., 1.), (0., 1., 1.), (0., 1., 0.)],
            Vec3::NEG_X,
        ),
        (
            [(1., 0., 0.), (1., 1., 0.), (1., 1., 1.), (1., 0., 1.)],
            Vec3::X,
        ),
        (
            [(0., 0., 0.), (0., 1., 0.), (1., 1., 0.), (1., 0., 0.)],
            Vec3::NEG_Z,
        ),
        (
            [(0., 0., 1.), (1., 0., 1.), (1., 1., 1.), (0., 1., 1.)],
            Vec3::Z,
        ),
    ];
    for (c, n) in faces {
        add(7, c.map(|(x, y, z)| cube(x, y, z)), n, 0, true);
    }
    // The sphere mover, object 8 (the bunny's stand-in).
    receivers.push(Receiver {
        object: 8,
        shape: ReceiverShape::Object {
            center: v(4.5, 0.5, 4.5),
            radius: 0.45,
        },
    });
    blockers.push(Blocker {
        object: 8,
        shape: Shape::Sphere {
            center: v(4.5, 0.5, 4.5),
            radius: 0.45,
        },
    });
    (receivers, blockers)
}

/// Lights on the room's surfaces facing in (as light samples are), one omni near the ceiling.
pub fn lights() -> Vec<PointLight> {
    let mut out = vec![PointLight {
        position: Vec3::new(3.1, 2.7, 2.9),
        normal: None,
    }];
    let mut rng = gibench_test_support::Lcg::new(1);
    let mut next = || rng.next_f32();
    for i in 0..48 {
        let (a, b) = (0.2 + 5.6 * next(), 0.2 + 5.6 * next());
        let (position, normal) = match i % 4 {
            0 => (Vec3::new(a, 0.001, b), Vec3::Y),
            1 => (Vec3::new(a, 2.999, b), Vec3::NEG_Y),
            2 => (Vec3::new(0.001, 0.2 + 2.6 * next(), b), Vec3::X),
            _ => (Vec3::new(a, 0.2 + 2.6 * next(), 5.999), Vec3::NEG_Z),
        };
        out.push(PointLight {
            position,
            normal: Some(normal),
        });
    }
    out
}

/// The patch leaf of `db` that `p` (normal `n`) lies in, at least `margin` inside its edges in
/// its (s, t), and where: (receiver, node, s, t). `tolerance`: largest distance off the plane.
pub fn leaf_at(
    db: &VisibilityDatabase,
    p: Vec3,
    n: Vec3,
    tolerance: f32,
    margin: f32,
) -> Option<(usize, usize, f32, f32)> {
    let mut found = None;
    for (r, receiver) in db.receivers.iter().enumerate() {
        let ReceiverShape::Patch(tree) = &receiver.shape else {
            continue;
        };
        if tree.normal.dot(n) < 0.99 {
            continue;
        }
        for node in tree.leaves() {
            let [a, b, _, d] = tree.nodes[node].corners;
            let (u, v, w) = (b - a, d - a, p - a);
            if tree.normal.dot(w).abs() > tolerance {
                continue;
            }
            let (s, t) = (w.dot(u) / u.length_squared(), w.dot(v) / v.length_squared());
            if (margin..=1.0 - margin).contains(&s) && (margin..=1.0 - margin).contains(&t) {
                found = Some((r, node, s, t));
            }
        }
    }
    found
}

/// A `res`² light map (row by row) at (s, t), bilinear between texel centres, clamped inside:
/// what `lightmap.wgsl` computes.
pub fn bilinear(texels: &[Vec3], res: u32, s: f32, t: f32) -> Vec3 {
    let last = (res - 1) as f32;
    let x = (s * res as f32 - 0.5).clamp(0.0, last);
    let y = (t * res as f32 - 0.5).clamp(0.0, last);
    let (i0, j0) = (x.floor() as u32, y.floor() as u32);
    let (i1, j1) = ((i0 + 1).min(res - 1), (j0 + 1).min(res - 1));
    let at = |i: u32, j: u32| texels[(j * res + i) as usize];
    let (fx, fy) = (x - i0 as f32, y - j0 as f32);
    at(i0, j0)
        .lerp(at(i1, j0), fx)
        .lerp(at(i0, j1).lerp(at(i1, j1), fx), fy)
}

/// Frame `f` rendered by `r` after the harness's G-buffer (the harness's uniforms written for
/// the frame), its output read back, and what the frame did.
pub fn render_frame(
    gpu: &GpuContext,
    harness: &Harness,
    r: &mut gibench_barczak::renderer::Renderer,
    f: u32,
) -> (Vec<[f32; 3]>, gibench_barczak::renderer::FrameCounts) {
    let frame = harness.clock.frame(f);
    harness.uniforms.write(&gpu.queue, &frame);
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    harness
        .gbuffer
        .encode(&mut enc, &harness.gpu_scene, &harness.uniforms);
    let counts = r
        .frame(
            gpu,
            &mut enc,
            &harness.gpu_scene,
            &harness.uniforms,
            &harness.bvh,
            &frame,
        )
        .unwrap();
    gpu.queue.submit([enc.finish()]);
    (
        gibench_harness::gpu::image_io::read_rgb_f32(gpu, r.output()).unwrap(),
        counts,
    )
}

/// `setup::prepare` of `scene` at `frame` (its light) with `settings`, light maps of `res`,
/// the default chart limit.
pub fn prepared(
    scene: &Scene,
    bvh: &gibench_harness::cpu::bvh::SceneBvh,
    frame: &gibench_harness::scene::anim::FrameState,
    settings: gibench_barczak::samples::SampleSettings,
    res: u32,
) -> gibench_barczak::setup::BarczakScene {
    use gibench_barczak::setup::{prepare, LightMapSize, MAX_CHARTS};
    let light_maps = LightMapSize {
        res,
        max_bytes: u64::MAX,
    };
    prepare(
        scene,
        bvh,
        frame,
        &frame.light,
        settings,
        light_maps,
        MAX_CHARTS,
    )
    .unwrap()
}
