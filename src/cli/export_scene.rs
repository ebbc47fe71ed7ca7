//! `gibench export-scene`: one frame of a scene as plain files another renderer can load — a
//! binary PLY of the frame's triangles per material (world space, movers placed) and
//! `scene.json` with the camera, the light and each material's albedo; with `--rays N` also the
//! ray sets of [`crate::rays`]. Used by `scripts/compare_mitsuba.py` to render the reference's
//! scene in Mitsuba 3 and to cast the same rays there.

use std::path::PathBuf;

use clap::Args;
use gibench_harness::output::OutputSet;
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::{Scene, SceneDescriptor};
use gibench_harness::{Error, Result};

#[derive(Args)]
pub(crate) struct ExportArgs {
    /// Scene: a built-in name or a descriptor JSON.
    #[arg(long, default_value = "cornell")]
    scene: String,
    /// Animation frame.
    #[arg(long, default_value_t = 0)]
    frame: u32,
    /// Image size WIDTHxHEIGHT (recorded for the camera's aspect ratio).
    #[arg(long, default_value = "256x192")]
    resolution: String,
    /// Output directory (`scene.json`, `mesh-K.ply`).
    #[arg(long)]
    out: PathBuf,
    /// Extra directory searched first for scene assets.
    #[arg(long)]
    assets: Option<PathBuf>,
    /// Also write this many closest-hit and this many shadow rays for `gibench raycast` and
    /// another ray caster (`rays-closest.bin`, `rays-shadow.bin`; see `src/rays.rs`).
    #[arg(long, default_value_t = 0)]
    rays: u32,
}

/// One material's triangles: their corners, the triangles as indices into them, and the map
/// from the frame mesh's vertex index to that list (`u32::MAX`: not used yet).
type Group = (Vec<[f32; 3]>, Vec<[u32; 3]>, Vec<u32>);

/// A binary little-endian PLY of `positions` and the triangles `tris` (indices into them).
fn ply(positions: &[[f32; 3]], tris: &[[u32; 3]]) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\ncomment gibench export-scene\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        positions.len(),
        tris.len()
    )
    .into_bytes();
    for p in positions {
        for c in p {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    for t in tris {
        out.push(3);
        for i in t {
            out.extend_from_slice(&(*i as i32).to_le_bytes());
        }
    }
    out
}

pub(crate) fn exec(args: &ExportArgs) -> Result<()> {
    let resolution = gibench_papers::params::parse_resolution(&args.resolution)?;
    gibench_harness::run::runner::check_resolution(resolution)?;
    gibench_papers::params::check_frame_number("frame", args.frame)?;
    if args.rays > crate::rays::MAX_RAYS {
        return Err(Error::param(
            "rays",
            format!(
                "{} exceeds the limit of {} per set (each set is held in memory, {} bytes a ray)",
                args.rays,
                crate::rays::MAX_RAYS,
                crate::rays::RAY_BYTES
            ),
        ));
    }
    let desc = SceneDescriptor::resolve(&args.scene)?;
    let scene = Scene::load(&desc, &AssetPaths::standard(args.assets.as_deref()))?;
    gibench_papers::files::writable_dir("out", &args.out)?;
    let frame = gibench_harness::scene::anim::FrameClock::new(&desc).frame(args.frame);
    let mesh = gibench_harness::cpu::reference::frame_mesh(&scene, &frame);
    // Triangles per material (a triangle's material is its first vertex's), each with its
    // own compact vertex list.
    let mut groups: Vec<Group> = (0..scene.materials.len())
        .map(|_| (Vec::new(), Vec::new(), vec![u32::MAX; mesh.positions.len()]))
        .collect();
    for t in mesh.indices.chunks_exact(3) {
        let m = mesh.materials[t[0] as usize] as usize;
        let Some((positions, tris, remap)) = groups.get_mut(m) else {
            return Err(Error::Invalid(format!(
                "scene '{}': a triangle names material {m}, beyond its {} materials",
                desc.name,
                scene.materials.len()
            )));
        };
        let mut tri = [0u32; 3];
        for (k, &v) in t.iter().enumerate() {
            if remap[v as usize] == u32::MAX {
                remap[v as usize] = positions.len() as u32;
                positions.push(mesh.positions[v as usize].to_array());
            }
            tri[k] = remap[v as usize];
        }
        tris.push(tri);
    }
    let rays = if args.rays > 0 {
        Some(crate::rays::make_rays(
            &scene, &frame, resolution, args.rays,
        )?)
    } else {
        None
    };
    let set = OutputSet::begin("out", &args.out)?;
    // A previous export's meshes and rays that this one does not write are removed with it.
    set.replace_files("mesh-*.ply")?;
    set.replace_files("rays-*.bin")?;
    if let Some((closest, shadow)) = &rays {
        gibench_harness::output::write_atomic(&args.out.join(crate::rays::CLOSEST), closest)?;
        gibench_harness::output::write_atomic(&args.out.join(crate::rays::SHADOW), shadow)?;
    }
    let mut materials = Vec::new();
    for (k, ((positions, tris, _), material)) in groups.iter().zip(&scene.materials).enumerate() {
        if tris.is_empty() {
            continue;
        }
        let file = format!("mesh-{k}.ply");
        gibench_harness::output::write_atomic(&args.out.join(&file), &ply(positions, tris))?;
        materials.push(serde_json::json!({
            "file": file, "name": material.name, "albedo": material.average_color.to_array(),
            "textured": material.texture.is_some(), "triangles": tris.len(),
        }));
    }
    let c = &frame.camera;
    let l = &frame.light;
    let json = serde_json::json!({
        "scene": desc.name, "scene_argument": args.scene, "frame": args.frame, "resolution": resolution,
        "rays": args.rays,
        "triangles": mesh.indices.len() / 3,
        "camera": {
            "origin": c.position.to_array(), "target": c.target.to_array(), "up": c.up.to_array(),
            "fov_y_deg": c.fov_y_rad.to_degrees(),
        },
        "light": {
            "kind": format!("{:?}", l.kind).to_lowercase(),
            "position": l.position.to_array(), "direction": l.direction.to_array(),
            "power": l.power.to_array(), "intensity": l.axis_intensity().to_array(), "size": l.size,
        },
        "materials": materials,
        "notes": "albedo: each material's average colour (its base colour times its texture's mean), \
                  which VPLs use; the reference looks textures up per hit. intensity: W/sr along the \
                  light's axis (spot: a cosine lobe about it; omni: every direction).",
    });
    let bytes = serde_json::to_vec_pretty(&json).map_err(|e| Error::Invalid(e.to_string()))?;
    gibench_harness::output::write_atomic(&args.out.join("scene.json"), &bytes)?;
    set.publish()?;
    eprintln!(
        "wrote {} ({} triangles in {} meshes)",
        args.out.join("scene.json").display(),
        mesh.indices.len() / 3,
        materials.len()
    );
    Ok(())
}
