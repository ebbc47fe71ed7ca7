//! Interleaved sampling (split, accumulate convention, combine, geometry-aware filter) on the
//! Cornell box G-buffer, on both Vulkan (lavapipe) and GL (llvmpipe). The filter writes its
//! output through a `texture_storage_2d<rgba16float, write>` binding, which these tests read
//! back on both backends.

use gibench_harness::glam::Vec3;
use gibench_harness::gpu::GpuContext;
use gibench_harness::kit::ir::interleave::{FilterSettings, Interleave, INTERLEAVE_WGSL};
use gibench_harness::kit::passes::{shader_module, GBufferTexels};
use gibench_harness::run::runner::Harness;
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::Scene;
use gibench_harness::wgpu;
use gibench_harness::Error;
use gibench_test_support::{backend_context, backends_for};

const CORNELL: FilterSettings = FilterSettings {
    alpha: 30.0,
    beta: 0.8,
};

const PERMISSIVE: FilterSettings = FilterSettings {
    alpha: f32::MAX,
    beta: -2.0,
};

/// Builds a harness on the Cornell box at `resolution`, renders the G-buffer of frame 17 and
/// hands the harness and the exported G-buffer to `f`.
fn with_cornell(gpu: &GpuContext, resolution: [u32; 2], f: impl FnOnce(&Harness, &GBufferTexels)) {
    let scene = Scene::load_named("cornell", &AssetPaths::standard(None)).unwrap();
    let config = gibench_test_support::one_frame(resolution)
        .shadow_size(64)
        .build();
    let h = Harness::new(gpu, &scene, &config).unwrap();
    let frame = h.clock.frame(17);
    h.uniforms.write(&gpu.queue, &frame);
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    h.gbuffer.encode(&mut enc, &h.gpu_scene, &h.uniforms);
    gpu.queue.submit([enc.finish()]);
    let g = h.gbuffer.export(gpu).unwrap();
    f(&h, &g);
}

fn output_texture(gpu: &GpuContext, size: [u32; 2]) -> wgpu::Texture {
    gibench_harness::kit::passes::indirect_target(&gpu.device, size, true)
}

/// Reads a buffer of `vec4<f32>` back to the CPU.
fn read_vec4(gpu: &GpuContext, buffer: &wgpu::Buffer) -> Vec<[f32; 4]> {
    let size = buffer.size();
    let readback = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("test readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    enc.copy_buffer_to_buffer(buffer, 0, &readback, 0, size);
    gpu.queue.submit([enc.finish()]);
    let slice = readback.slice(..);
    slice.map_async(wgpu::MapMode::Read, |_| {});
    gpu.flush().unwrap();
    let bytes = slice.get_mapped_range().unwrap().to_vec();
    readback.unmap();
    bytes
        .chunks_exact(16)
        .map(|c| {
            let f =
                |i: usize| f32::from_le_bytes([c[4 * i], c[4 * i + 1], c[4 * i + 2], c[4 * i + 3]]);
            [f(0), f(1), f(2), f(3)]
        })
        .collect()
}

/// Writes one rgb value per pixel into `combined` (a = 1).
fn write_combined(gpu: &GpuContext, inter: &Interleave, rgb: &[[f32; 3]]) {
    let bytes: Vec<u8> = rgb
        .iter()
        .flat_map(|v| [v[0], v[1], v[2], 1.0])
        .flat_map(f32::to_le_bytes)
        .collect();
    assert_eq!(bytes.len() as u64, inter.combined.size());
    gpu.queue.write_buffer(&inter.combined, 0, &bytes);
}

/// Runs the split (the filter reads its surfaces from the split buffers), then the filter on
/// `input`, and reads `output` back.
fn filter(
    gpu: &GpuContext,
    inter: &Interleave,
    output: &wgpu::Texture,
    input: &[[f32; 3]],
) -> Vec<[f32; 3]> {
    write_combined(gpu, inter, input);
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    inter.encode_split(&mut enc);
    inter.encode_filter(&mut enc);
    gpu.queue.submit([enc.finish()]);
    let out = gibench_harness::gpu::image_io::read_rgb_f32(gpu, output).unwrap();
    gpu.check_errors().unwrap();
    out
}

fn close(a: f32, b: f32, rel: f32) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) || a.to_bits() == b.to_bits()
}

/// Split, then copy `split_position` into `split_irradiance`, then combine: `combined` holds
/// the G-buffer's world positions (bit-identical, or within 1e-6 relative) at every hit pixel
/// and w = 0 elsewhere. Also checks the split layout itself against the definition.
#[test]
fn split_then_combine_is_identity() {
    for backend in backends_for("interleave") {
        let gpu = backend_context(backend);
        for size in [[96, 72], [97, 70]] {
            with_cornell(&gpu, size, |h, g| {
                let [w, ht] = size;
                let output = output_texture(&gpu, size);
                for tiles in [(4, 4), (3, 2), (1, 1), (8, 8), (5, 3)] {
                    let what = format!("{backend} {w}x{ht} tiles {tiles:?}");
                    let inter = Interleave::new(&gpu, &h.gbuffer, tiles, CORNELL, &output)
                        .unwrap_or_else(|e| panic!("{what}: {e}"));
                    let [n, m] = [tiles.0, tiles.1];
                    let [tw, th] = [w.div_ceil(n), ht.div_ceil(m)];
                    assert_eq!(inter.tile_size, [tw, th], "{what}");
                    assert_eq!(inter.split_size, [n * tw, m * th], "{what}");
                    let mut enc = gpu.device.create_command_encoder(&Default::default());
                    inter.encode_split(&mut enc);
                    enc.copy_buffer_to_buffer(
                        &inter.split_position,
                        0,
                        &inter.split_irradiance,
                        0,
                        inter.split_position.size(),
                    );
                    inter.encode_combine(&mut enc);
                    gpu.queue.submit([enc.finish()]);
                    let split_pos = read_vec4(&gpu, &inter.split_position);
                    let split_nrm = read_vec4(&gpu, &inter.split_normal);
                    let combined = read_vec4(&gpu, &inter.combined);
                    gpu.check_errors().unwrap();

                    // The split texels hold the pixels the definition says.
                    let [sw, sh] = inter.split_size;
                    assert_eq!(split_pos.len(), (sw * sh) as usize, "{what}");
                    let mut hits = 0;
                    for sy in 0..sh {
                        for sx in 0..sw {
                            let s = (sy * sw + sx) as usize;
                            let (i, j, a, b) = (sx / tw, sy / th, sx % tw, sy % th);
                            let (x, y) = (a * n + i, b * m + j);
                            let hit = (x < w && y < ht)
                                .then(|| g.positions[(y * w + x) as usize])
                                .flatten();
                            match hit {
                                Some(p) => {
                                    hits += 1;
                                    let q = split_pos[s];
                                    assert_eq!(q[3], 1.0, "{what}: split ({sx}, {sy})");
                                    for c in 0..3 {
                                        assert!(
                                            close(q[c], p[c], 1e-6),
                                            "{what}: split ({sx}, {sy}) holds {q:?}, pixel ({x}, {y}) is at {p}"
                                        );
                                    }
                                    let nrm = g.normals[(y * w + x) as usize];
                                    let sn = split_nrm[s];
                                    assert_eq!(
                                        [sn[0], sn[1], sn[2], sn[3]],
                                        [nrm.x, nrm.y, nrm.z, 0.0],
                                        "{what}: split normal ({sx}, {sy})"
                                    );
                                }
                                None => {
                                    assert_eq!(split_pos[s], [0.0; 4], "{what}: ({sx}, {sy})");
                                    assert_eq!(split_nrm[s], [0.0; 4], "{what}: ({sx}, {sy})");
                                }
                            }
                        }
                    }
                    assert!(hits > (w * ht / 2) as usize, "{what}: only {hits} hits");

                    // Combine is the inverse of split.
                    assert_eq!(combined.len(), (w * ht) as usize, "{what}");
                    for (i, (c, p)) in combined.iter().zip(&g.positions).enumerate() {
                        let (x, y) = (i as u32 % w, i as u32 / w);
                        match p {
                            Some(p) => {
                                assert_eq!(c[3], 1.0, "{what}: pixel ({x}, {y})");
                                for k in 0..3 {
                                    assert!(
                                        close(c[k], p[k], 1e-6),
                                        "{what}: pixel ({x}, {y}) combined {c:?}, G-buffer {p}"
                                    );
                                }
                            }
                            None => assert_eq!(c[3], 0.0, "{what}: pixel ({x}, {y})"),
                        }
                    }
                }
            });
        }
    }
}

/// A technique-style accumulate shader built from `INTERLEAVE_WGSL` and bound with
/// `split_layout`/`split_group`, dispatched with `dispatch_split_size`, sees each texel's tile
/// j·n + i and original pixel; after combining, pixel (x, y) carries tile (y % m)·n + x % n.
#[test]
fn accumulate_convention_sees_tiles_and_pixels() {
    const SHADER: &str = r#"
@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (!split_in_range(id.x, id.y)) {
        return;
    }
    let i = split_index(id.x, id.y);
    let p = split_original_pixel(id.x, id.y);
    var valid = 0.0;
    if (split_valid(id.x, id.y)) {
        valid = 1.0;
    }
    let back = split_texel_of_pixel(p.x, p.y);
    if (any(back != id.xy)) {
        valid = -1.0;
    }
    split_irradiance[i] = vec4<f32>(f32(split_tile(id.x, id.y)), f32(p.x), f32(p.y),
        valid + 2.0 * split_position[i].w + 4.0 * split_normal[i].w);
}
"#;
    for backend in backends_for("interleave") {
        let gpu = backend_context(backend);
        let size = [97, 70];
        with_cornell(&gpu, size, |h, g| {
            let output = output_texture(&gpu, size);
            for tiles in [(4, 4), (3, 2), (1, 1), (8, 8)] {
                let what = format!("{backend} tiles {tiles:?}");
                let inter = Interleave::new(&gpu, &h.gbuffer, tiles, CORNELL, &output).unwrap();
                let device = &gpu.device;
                let module = shader_module(
                    device,
                    "test accumulate",
                    &format!("{INTERLEAVE_WGSL}\n{SHADER}"),
                );
                let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: None,
                    bind_group_layouts: &[Some(inter.split_layout())],
                    immediate_size: 0,
                });
                let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some("test accumulate"),
                    layout: Some(&layout),
                    module: &module,
                    entry_point: Some("main"),
                    compilation_options: Default::default(),
                    cache: None,
                });
                let mut enc = device.create_command_encoder(&Default::default());
                inter.encode_split(&mut enc);
                {
                    let mut pass = enc.begin_compute_pass(&Default::default());
                    pass.set_pipeline(&pipeline);
                    pass.set_bind_group(0, inter.split_group(), &[]);
                    inter.dispatch_split_size(&mut pass);
                }
                inter.encode_combine(&mut enc);
                gpu.queue.submit([enc.finish()]);
                let combined = read_vec4(&gpu, &inter.combined);
                gpu.check_errors().unwrap();
                let (n, m) = tiles;
                for (i, c) in combined.iter().enumerate() {
                    let (x, y) = (i as u32 % size[0], i as u32 / size[0]);
                    let hit = if g.positions[i].is_some() { 2.0 } else { 0.0 };
                    let want = [((y % m) * n + x % n) as f32, x as f32, y as f32, 1.0 + hit];
                    assert_eq!(*c, want, "{what}: pixel ({x}, {y})");
                }
            }
        });
    }
}

/// Groups hit pixels into planes (normal within 2.6°, plane offset within 5 units): a
/// surface id per pixel (None for background).
fn plane_ids(g: &GBufferTexels) -> Vec<Option<usize>> {
    let mut planes: Vec<(Vec3, f32)> = Vec::new();
    g.positions
        .iter()
        .zip(&g.normals)
        .map(|(p, n)| {
            let p = (*p)?;
            let d = n.dot(p);
            let id = planes
                .iter()
                .position(|(pn, pd)| pn.dot(*n) > 0.999 && (pd - d).abs() < 5.0);
            Some(id.unwrap_or_else(|| {
                planes.push((*n, d));
                planes.len() - 1
            }))
        })
        .collect()
}

/// The filter keeps a value that is constant per planar surface exactly (its support never
/// crosses a depth or normal discontinuity with the Cornell thresholds), and it does not mix the
/// short block's top with the floor behind it (same normal, a depth step) unless α is large
/// enough to cross the step.
#[test]
fn filter_respects_discontinuities() {
    for backend in backends_for("interleave") {
        let gpu = backend_context(backend);
        for size in [[96, 72], [97, 70]] {
            with_cornell(&gpu, size, |h, g| {
                let output = output_texture(&gpu, size);
                let ids = plane_ids(g);
                let planes = ids.iter().flatten().max().unwrap() + 1;
                assert!(planes >= 8, "only {planes} planes in view");
                // Small integers: exact in half floats, so any mixing shows.
                let per_surface: Vec<[f32; 3]> = ids
                    .iter()
                    .map(|id| match id {
                        Some(k) => [(k + 1) as f32, (2 * k + 3) as f32, 0.5],
                        None => [1000.0; 3],
                    })
                    .collect();
                // 1 on the blocks (their tops, and their sides, which are not axis-aligned), 0 on
                // the box (walls, floor, ceiling: axis-aligned) and background. Where a block
                // face stands in front of a wall its normal is within about 17° of the wall's
                // (passes β): only α keeps them apart.
                let blocks: Vec<[f32; 3]> = g
                    .positions
                    .iter()
                    .zip(&g.normals)
                    .map(|(p, n)| match p {
                        Some(p) if n.y > 0.9 && p.y > 50.0 => [1.0; 3],
                        Some(_) if n.abs().max_element() < 0.99 => [1.0; 3],
                        _ => [0.0; 3],
                    })
                    .collect();
                let on_blocks = blocks.iter().filter(|t| t[0] == 1.0).count();
                assert!(on_blocks > 100, "only {on_blocks} block pixels in view");
                for tiles in [(4, 4), (3, 2), (1, 1), (8, 8)] {
                    let what = format!("{backend} {size:?} tiles {tiles:?}");
                    let mut inter =
                        Interleave::new(&gpu, &h.gbuffer, tiles, CORNELL, &output).unwrap();
                    let out = filter(&gpu, &inter, &output, &per_surface);
                    for (i, (o, v)) in out.iter().zip(&per_surface).enumerate() {
                        let want = if g.positions[i].is_some() {
                            *v
                        } else {
                            [0.0; 3]
                        };
                        assert_eq!(
                            *o,
                            want,
                            "{what}: pixel ({}, {}) mixes surfaces",
                            i % size[0] as usize,
                            i / size[0] as usize
                        );
                    }
                    let out = filter(&gpu, &inter, &output, &blocks);
                    for (i, (o, v)) in out.iter().zip(&blocks).enumerate() {
                        assert_eq!(
                            o,
                            v,
                            "{what}: pixel ({}, {}) mixes a block with the box",
                            i % size[0] as usize,
                            i / size[0] as usize
                        );
                    }
                    if tiles != (1, 1) {
                        // The checks have teeth: permissive thresholds mix surfaces, and
                        inter.set_filter(&gpu.queue, PERMISSIVE).unwrap();
                        let out = filter(&gpu, &inter, &output, &per_surface);
                        assert!(
                            out.iter().zip(&per_surface).any(|(o, v)| o != v),
                            "{what}: no pixel near a surface boundary"
                        );
                        // the blocks and the box mix: with α across the step the two do mix.
                        inter
                            .set_filter(
                                &gpu.queue,
                                FilterSettings {
                                    alpha: 1e6,
                                    beta: 0.8,
                                },
                            )
                            .unwrap();
                        let out = filter(&gpu, &inter, &output, &blocks);
                        assert!(
                            out.iter().any(|o| o[0] > 0.0 && o[0] < 1.0),
                            "{what}: no pixel near a depth step"
                        );
                    }
                }
            });
        }
    }
}

/// A constant input comes out unchanged at every hit pixel, borders included (the average is
/// normalised by the taps actually taken), with permissive and with the Cornell thresholds;
/// background pixels are 0.
#[test]
fn filter_preserves_a_constant() {
    for backend in backends_for("interleave") {
        let gpu = backend_context(backend);
        for size in [[96, 72], [97, 70]] {
            with_cornell(&gpu, size, |h, g| {
                let output = output_texture(&gpu, size);
                let input = vec![[0.75f32, 1.5, 3.0]; (size[0] * size[1]) as usize];
                for tiles in [(4, 4), (3, 2), (1, 1), (8, 8), (5, 3)] {
                    for settings in [PERMISSIVE, CORNELL] {
                        let what = format!("{backend} {size:?} tiles {tiles:?} {settings:?}");
                        let inter =
                            Interleave::new(&gpu, &h.gbuffer, tiles, settings, &output).unwrap();
                        let out = filter(&gpu, &inter, &output, &input);
                        for (i, o) in out.iter().enumerate() {
                            let want = if g.positions[i].is_some() {
                                input[i]
                            } else {
                                [0.0; 3]
                            };
                            assert_eq!(
                                *o,
                                want,
                                "{what}: pixel ({}, {})",
                                i % size[0] as usize,
                                i / size[0] as usize
                            );
                        }
                    }
                }
            });
        }
    }
}

/// Laine et al. 2007, Figure 5 on the CPU, with the box shifted inside the image at borders.
/// None where a tap's distance or cosine lies within rounding of a threshold.
fn cpu_filter(
    g: &GBufferTexels,
    input: &[[f32; 3]],
    tiles: (u32, u32),
    f: FilterSettings,
) -> Vec<Option<[f32; 3]>> {
    let [w, h] = g.size;
    let (n, m) = (tiles.0 as i64, tiles.1 as i64);
    let (w, h) = (w as i64, h as i64);
    let mut out = Vec::new();
    for py in 0..h {
        for px in 0..w {
            let i = (py * w + px) as usize;
            let Some(p) = g.positions[i] else {
                out.push(Some([0.0; 3]));
                continue;
            };
            let nrm = g.normals[i];
            let ox = (px - n / 2).clamp(0, (w - n).max(0));
            let oy = (py - m / 2).clamp(0, (h - m).max(0));
            let (mut acc, mut count, mut ambiguous) = ([0.0f64; 3], 0.0f64, false);
            for ty in oy..(oy + m).min(h) {
                for tx in ox..(ox + n).min(w) {
                    let t = (ty * w + tx) as usize;
                    let take = if t == i {
                        true
                    } else if let Some(q) = g.positions[t] {
                        let d = (q - p).length();
                        let c = g.normals[t].dot(nrm);
                        ambiguous |= (d - f.alpha).abs() < 1e-3 * (1.0 + f.alpha)
                            || (c - f.beta).abs() < 1e-3;
                        d < f.alpha && c > f.beta
                    } else {
                        false
                    };
                    if take {
                        for k in 0..3 {
                            acc[k] += input[t][k] as f64;
                        }
                        count += 1.0;
                    }
                }
            }
            out.push((!ambiguous).then(|| acc.map(|a| (a / count) as f32)));
        }
    }
    out
}

/// The GPU filter matches a CPU implementation of Figure 5 on a noisy input.
#[test]
fn filter_matches_cpu_reference() {
    for backend in backends_for("interleave") {
        let gpu = backend_context(backend);
        let size = [97, 70];
        with_cornell(&gpu, size, |h, g| {
            let output = output_texture(&gpu, size);
            let mut state = 12345u32;
            let input: Vec<[f32; 3]> = (0..size[0] * size[1])
                .map(|_| {
                    let mut r = || {
                        state ^= state << 13;
                        state ^= state >> 17;
                        state ^= state << 5;
                        (state >> 8) as f32 / (1u32 << 24) as f32
                    };
                    [r(), r(), r()]
                })
                .collect();
            for tiles in [(4, 4), (3, 2), (1, 1), (8, 8), (5, 3)] {
                let what = format!("{backend} tiles {tiles:?}");
                let inter = Interleave::new(&gpu, &h.gbuffer, tiles, CORNELL, &output).unwrap();
                let out = filter(&gpu, &inter, &output, &input);
                let want = cpu_filter(g, &input, tiles, CORNELL);
                let mut compared = 0;
                for (i, (o, e)) in out.iter().zip(&want).enumerate() {
                    let Some(e) = e else { continue };
                    compared += 1;
                    for k in 0..3 {
                        assert!(
                            (o[k] - e[k]).abs() <= 1e-3 * e[k].abs().max(0.5),
                            "{what}: pixel ({}, {}): GPU {o:?}, CPU {e:?}",
                            i % size[0] as usize,
                            i / size[0] as usize
                        );
                    }
                }
                assert!(
                    compared * 100 >= want.len() * 95,
                    "{what}: {compared} compared"
                );
            }
        });
    }
}

/// The filter's taps addressed from the box origin's quotient and remainder give the very
/// output of the form it replaced (`interleave_passes_by_division.wgsl`: a division and a
/// modulo per tap), bit for bit, for tile grids that wrap at every column and row, clip at the
/// borders, and span most of the image (64x64 on 97x70). Catches a remainder that wraps one
/// tap late or a quotient not carried (tried: the wrap test `>` instead of `>=` differs).
#[test]
fn the_filter_equals_its_division_form() {
    for backend in backends_for("interleave") {
        let gpu = backend_context(backend);
        let size = [97, 70];
        with_cornell(&gpu, size, |h, _| {
            let input: Vec<[f32; 3]> = (0..size[0] * size[1])
                .map(|i| {
                    [
                        (i % 13) as f32 * 0.1,
                        (i % 7) as f32 * 0.3,
                        (i % 29) as f32 * 0.05,
                    ]
                })
                .collect();
            for tiles in [(4, 4), (3, 2), (1, 1), (8, 8), (5, 3), (64, 64)] {
                let [a, b] = [output_texture(&gpu, size), output_texture(&gpu, size)];
                let lean = Interleave::new(&gpu, &h.gbuffer, tiles, CORNELL, &a).unwrap();
                let division = Interleave::with_passes_source(
                    &gpu,
                    &h.gbuffer,
                    tiles,
                    CORNELL,
                    &b,
                    include_str!("interleave_passes_by_division.wgsl"),
                )
                .unwrap();
                let x = filter(&gpu, &lean, &a, &input);
                let y = filter(&gpu, &division, &b, &input);
                let differ = (x.iter().zip(&y))
                    .filter(|(p, q)| p.map(f32::to_bits) != q.map(f32::to_bits))
                    .count();
                assert_eq!(
                    differ, 0,
                    "{backend} tiles {tiles:?}: {differ} pixels differ"
                );
                assert!(
                    x.iter().filter(|p| p.iter().any(|v| *v > 0.0)).count() > x.len() / 2,
                    "{backend} tiles {tiles:?}: the filter wrote little"
                );
            }
        });
    }
}

fn expect_param_error(result: Result<Interleave, Error>, name: &str, what: &str) {
    match result {
        Err(Error::Param { name: n, message }) => {
            assert_eq!(n, name, "{what}: {message}");
            eprintln!("{what}: {message}");
        }
        Err(e) => panic!("{what}: wrong error {e}"),
        Ok(_) => panic!("{what}: accepted"),
    }
}

/// Bad tile counts and a wrongly sized, formatted or flagged output texture are rejected with
/// errors naming the parameter.
#[test]
fn rejects_bad_parameters() {
    for backend in backends_for("interleave") {
        let gpu = backend_context(backend);
        let size = [96, 72];
        with_cornell(&gpu, size, |h, _| {
            let output = output_texture(&gpu, size);
            for tiles in [(0, 4), (65, 1), (4, 0), (1, 65)] {
                let r = Interleave::new(&gpu, &h.gbuffer, tiles, CORNELL, &output);
                expect_param_error(r, "tiles", &format!("{backend} tiles {tiles:?}"));
            }
            assert!(Interleave::new(&gpu, &h.gbuffer, (64, 64), CORNELL, &output).is_ok());
            let wrong = output_texture(&gpu, [95, 72]);
            let r = Interleave::new(&gpu, &h.gbuffer, (4, 4), CORNELL, &wrong);
            expect_param_error(r, "output", &format!("{backend} output size"));
            let no_storage = gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: None,
                size: wgpu::Extent3d {
                    width: size[0],
                    height: size[1],
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba16Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            });
            let r = Interleave::new(&gpu, &h.gbuffer, (4, 4), CORNELL, &no_storage);
            expect_param_error(r, "output", &format!("{backend} output usage"));
            gpu.check_errors().unwrap();
        });
    }
}
