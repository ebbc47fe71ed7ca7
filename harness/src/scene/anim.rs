//! The deterministic animation clock: frame `i` is at time `i / fps` and has exactly one camera
//! pose, one primary-light pose and one transform per mover, computed from the descriptor's
//! keyframed paths. Every technique sees the same frames.

use glam::{Mat4, Vec3};

use crate::scene::descriptor::{LightKind, PathDesc, SceneDescriptor};

/// Right-handed world → view matrix (view looks down −Z, +Y up).
pub fn look_at(eye: Vec3, target: Vec3, up: Vec3) -> Mat4 {
    glam::camera::rh::view::look_at_mat4(eye, target, up)
}

/// Reversed-Z infinite perspective projection for wgpu's clip space (NDC y up, z in [0, 1]):
/// depth 1 at the near plane, 0 at infinity.
pub fn perspective_reverse_z(fov_y_rad: f32, aspect: f32, near: f32) -> Mat4 {
    glam::camera::rh::proj::directx::perspective_infinite_reverse(fov_y_rad, aspect, near)
}

/// Where the camera is in one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraPose {
    pub position: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    pub fov_y_rad: f32,
    pub near: f32,
}

impl CameraPose {
    /// World → view (right-handed, looking down −Z).
    pub fn view(&self) -> Mat4 {
        look_at(self.position, self.target, self.up)
    }
    /// Reversed-Z infinite perspective projection (depth 1 at the near plane, 0 at infinity),
    /// which keeps depth precise at every distance.
    pub fn projection(&self, aspect: f32) -> Mat4 {
        perspective_reverse_z(self.fov_y_rad, aspect, self.near)
    }
    /// Unit viewing direction.
    pub fn forward(&self) -> Vec3 {
        (self.target - self.position).normalize()
    }
}

/// The primary light in one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightPose {
    pub kind: LightKind,
    pub position: Vec3,
    /// Unit direction: spot axis, or area-light normal. Omni lights keep it too (unused).
    pub direction: Vec3,
    /// Total flux Φ, RGB.
    pub power: Vec3,
    /// Area lights: width, height (0 for point lights).
    pub size: [f32; 2],
}

/// Everything that moves, for one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameState {
    pub index: u32,
    pub time: f32,
    pub camera: CameraPose,
    pub light: LightPose,
    /// Object → world transform per mover, in descriptor order.
    pub movers: Vec<Mat4>,
}

/// Maps frame numbers to [`FrameState`]s for one scene.
#[derive(Clone, Debug)]
pub struct FrameClock {
    desc: SceneDescriptor,
}

/// A point on a path at time `t` (seconds): (position, target). The target is `Some` when every
/// key of the path has one. Times outside the path's span are wrapped by its [`Wrap`] mode:
/// `Loop` takes `t mod duration`, `PingPong` runs back and forth, `Clamp` holds the ends.
/// Interpolation is uniform Catmull–Rom (details in the implementation's docs); the result is
/// a pure function of its inputs, so the same inputs give bit-identical outputs.
///
/// [`Wrap`]: crate::scene::descriptor::Wrap
pub fn sample_path(path: &PathDesc, t: f32) -> (Vec3, Option<Vec3>) {
    imp::sample_path(path, t)
}

impl FrameClock {
    /// A clock for `desc` (copied). The descriptor is expected to be validated; invalid values
    /// never panic but may give degenerate poses.
    pub fn new(desc: &SceneDescriptor) -> Self {
        FrameClock { desc: desc.clone() }
    }
    /// The state of frame `index`, at time `index / fps`: the camera and light poses from their
    /// paths (camera up +Y, or +Z when looking nearly straight up or down; light direction
    /// towards its target, −Y for an untargeted omni light) and one rigid transform per mover
    /// (translation × rotation about +Y facing its target horizontally; the mover mesh is
    /// pre-scaled, see [`crate::scene::Mover`]).
    pub fn frame(&self, index: u32) -> FrameState {
        imp::frame(&self.desc, index)
    }
}

mod imp {
    use super::*;
    use crate::scene::descriptor::{Key, Wrap};

    /// Maps `t` into the path's time span `[0, duration]` according to its wrap mode.
    fn wrap_time(t: f32, duration: f32, wrap: Wrap) -> f32 {
        let t = if t.is_finite() { t } else { 0.0 };
        match wrap {
            Wrap::Clamp => t.clamp(0.0, duration),
            Wrap::Loop => t.rem_euclid(duration).min(duration),
            Wrap::PingPong => {
                let u = t.rem_euclid(2.0 * duration);
                (if u > duration { 2.0 * duration - u } else { u }).clamp(0.0, duration)
            }
        }
    }

    /// Whether two key points are the same within rounding (a loop that ends where it starts).
    fn same_point(a: [f32; 3], b: [f32; 3]) -> bool {
        let (a, b) = (Vec3::from(a), Vec3::from(b));
        (a - b).length() <= 1e-5 * a.abs().max_element().max(b.abs().max_element()).max(1.0)
    }

    /// Uniform Catmull–Rom between `p1` and `p2` at local parameter `s` in [0, 1].
    fn catmull_rom(p0: Vec3, p1: Vec3, p2: Vec3, p3: Vec3, s: f32) -> Vec3 {
        let s2 = s * s;
        let s3 = s2 * s;
        0.5 * ((2.0 * p1)
            + (p2 - p0) * s
            + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * s2
            + (3.0 * p1 - p0 - 3.0 * p2 + p3) * s3)
    }

    /// See [`super::sample_path`]. Between keys `i` and `i + 1` the position (and the target,
    /// when every key has one) follows a uniform Catmull–Rom spline through keys `i − 1 … i + 2`
    /// with local parameter `(t − tᵢ) / (tᵢ₊₁ − tᵢ)`. The neighbours beyond the ends are the end
    /// keys themselves (clamped tangents), except for a [`Wrap::Loop`] path that ends where it
    /// starts, whose neighbours wrap around (skipping the duplicated end key) so the motion is
    /// smooth across the wrap. The path lasts until its last key's time; a single key (or an
    /// empty path: the origin) is constant.
    pub fn sample_path(path: &PathDesc, t: f32) -> (Vec3, Option<Vec3>) {
        let keys: &[Key] = &path.keys;
        let has_target = !keys.is_empty() && keys.iter().all(|k| k.target.is_some());
        let target_of = |k: &Key| Vec3::from(k.target.unwrap_or(k.position));
        let n = keys.len();
        if n == 0 {
            return (Vec3::ZERO, None);
        }
        let duration = keys[n - 1].time - keys[0].time;
        if n == 1 || !(duration.is_finite() && duration > 0.0) {
            let k = &keys[0];
            return (Vec3::from(k.position), has_target.then(|| target_of(k)));
        }
        let t = keys[0].time + wrap_time(t - keys[0].time, duration, path.wrap);

        // Segment i: keys[i].time <= t <= keys[i + 1].time.
        let i = keys
            .partition_point(|k| k.time <= t)
            .saturating_sub(1)
            .min(n - 2);
        let (t0, t1) = (keys[i].time, keys[i + 1].time);
        let s = if t1 > t0 {
            ((t - t0) / (t1 - t0)).clamp(0.0, 1.0)
        } else {
            0.0
        };

        let cyclic = path.wrap == Wrap::Loop
            && n >= 3
            && same_point(keys[0].position, keys[n - 1].position)
            && (!has_target
                || same_point(target_of(&keys[0]).into(), target_of(&keys[n - 1]).into()));
        // Index of the neighbour key `j` (may be −1 or n).
        let neighbour = |j: isize| -> &Key {
            if cyclic {
                // Keys 0 and n − 1 coincide: the cycle has n − 1 distinct keys.
                let m = (n - 1) as isize;
                &keys[j.rem_euclid(m) as usize]
            } else {
                &keys[j.clamp(0, n as isize - 1) as usize]
            }
        };
        let i = i as isize;
        let quad = [
            neighbour(i - 1),
            neighbour(i),
            neighbour(i + 1),
            neighbour(i + 2),
        ];
        let pos = catmull_rom(
            quad[0].position.into(),
            quad[1].position.into(),
            quad[2].position.into(),
            quad[3].position.into(),
            s,
        );
        let target = has_target.then(|| {
            catmull_rom(
                target_of(quad[0]),
                target_of(quad[1]),
                target_of(quad[2]),
                target_of(quad[3]),
                s,
            )
        });
        (pos, target)
    }

    /// The frame's time: `index / fps` (0 if `fps` is not positive).
    fn frame_time(desc: &SceneDescriptor, index: u32) -> f32 {
        if desc.fps.is_finite() && desc.fps > 0.0 {
            (index as f64 / desc.fps as f64) as f32
        } else {
            0.0
        }
    }

    /// See [`super::FrameClock::frame`].
    ///
    /// * Camera: position and target from its path; up is +Y, or +Z when the view direction is
    ///   within about 2.6° of ±Y. A missing or coincident target looks along +Z.
    /// * Light: direction `normalize(target − position)`; omni lights without a target (and any
    ///   degenerate direction) point along −Y.
    /// * Movers: `translation(position) × rotation_y(atan2(dx, dz))`, where (dx, dz) is the
    ///   horizontal direction to the target (no rotation without a target). The mover's mesh is
    ///   already scaled by its `scale` when the scene is loaded, so the transform is rigid.
    pub fn frame(desc: &SceneDescriptor, index: u32) -> FrameState {
        let time = frame_time(desc, index);

        let (cam_pos, cam_target) = sample_path(&desc.camera.path, time);
        let mut target = cam_target.unwrap_or(cam_pos + Vec3::Z);
        if (target - cam_pos).length_squared() <= f32::MIN_POSITIVE || !target.is_finite() {
            target = cam_pos + Vec3::Z;
        }
        let forward = (target - cam_pos).normalize_or(Vec3::Z);
        let up = if forward.y.abs() > 0.999 {
            Vec3::Z
        } else {
            Vec3::Y
        };
        let camera = CameraPose {
            position: cam_pos,
            target,
            up,
            fov_y_rad: desc.camera.fov_y_deg.to_radians(),
            near: desc.camera.near,
        };

        let l = &desc.light;
        let (light_pos, light_target) = sample_path(&l.path, time);
        let direction =
            light_target.map_or(Vec3::NEG_Y, |t| (t - light_pos).normalize_or(Vec3::NEG_Y));
        let size = match l.kind {
            LightKind::Area => l.size.unwrap_or([0.0, 0.0]),
            _ => [0.0, 0.0],
        };
        let light = LightPose {
            kind: l.kind,
            position: light_pos,
            direction,
            power: Vec3::from(l.power),
            size,
        };

        let movers = desc
            .movers
            .iter()
            .map(|m| {
                let (pos, target) = sample_path(&m.path, time);
                let angle = match target {
                    Some(t) => {
                        let (dx, dz) = (t.x - pos.x, t.z - pos.z);
                        if dx * dx + dz * dz > 0.0 && dx.is_finite() && dz.is_finite() {
                            dx.atan2(dz)
                        } else {
                            0.0
                        }
                    }
                    None => 0.0,
                };
                Mat4::from_translation(pos) * Mat4::from_rotation_y(angle)
            })
            .collect();

        FrameState {
            index,
            time,
            camera,
            light,
            movers,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::descriptor::{Key, Wrap};

    fn path(wrap: Wrap, points: &[(f32, [f32; 3])]) -> PathDesc {
        PathDesc {
            wrap,
            keys: points
                .iter()
                .map(|&(time, position)| Key {
                    time,
                    position,
                    target: Some([position[0], 0.0, position[2] + 1.0]),
                })
                .collect(),
        }
    }

    fn square_loop() -> PathDesc {
        path(
            Wrap::Loop,
            &[
                (0.0, [0.0, 0.0, 0.0]),
                (1.0, [10.0, 0.0, 0.0]),
                (2.0, [10.0, 0.0, 10.0]),
                (3.0, [0.0, 5.0, 10.0]),
                (4.0, [0.0, 0.0, 0.0]),
            ],
        )
    }

    #[test]
    fn anim_frame_clock_is_deterministic() {
        for name in crate::scene::descriptor::builtin_names() {
            let d = SceneDescriptor::resolve(name).unwrap();
            let (a, b) = (FrameClock::new(&d), FrameClock::new(&d));
            for i in [0, 1, 7, 30, 299, 1000, 123_456] {
                let (fa, fb) = (a.frame(i), b.frame(i));
                assert_eq!(fa, fb);
                assert_eq!(
                    fa.camera.position.to_array().map(f32::to_bits),
                    fb.camera.position.to_array().map(f32::to_bits)
                );
                assert_eq!(
                    fa.light.direction.to_array().map(f32::to_bits),
                    fb.light.direction.to_array().map(f32::to_bits)
                );
                assert_eq!(fa.time, i as f32 / d.fps);
                assert_eq!(fa.index, i);
            }
        }
    }

    #[test]
    fn anim_passes_through_keys() {
        for wrap in [Wrap::Loop, Wrap::PingPong, Wrap::Clamp] {
            let mut p = square_loop();
            p.wrap = wrap;
            for k in &p.keys {
                let (pos, target) = sample_path(&p, k.time);
                assert!(
                    pos.abs_diff_eq(Vec3::from(k.position), 1e-4),
                    "{wrap:?} t={}: {pos}",
                    k.time
                );
                assert!(target
                    .unwrap()
                    .abs_diff_eq(Vec3::from(k.target.unwrap()), 1e-4));
            }
        }
        // Built-in paths too.
        let d = SceneDescriptor::resolve("cornell").unwrap();
        for k in &d.light.path.keys {
            let (pos, _) = sample_path(&d.light.path, k.time);
            assert!(pos.abs_diff_eq(Vec3::from(k.position), 1e-3), "{pos}");
        }
    }

    #[test]
    fn anim_loop_is_continuous_across_the_wrap() {
        let p = square_loop();
        let h = 1e-3;
        let at = |t: f32| sample_path(&p, t).0;
        // Position continuity.
        assert!(at(4.0 - h).distance(at(4.0 + h)) < 0.1);
        assert!(at(4.0 - h).distance(at(h)) < 0.1);
        // Velocity continuity: the tangent wraps around instead of being clamped.
        let v_before = (at(4.0 - h) - at(4.0 - 2.0 * h)) / h;
        let v_after = (at(4.0 + 2.0 * h) - at(4.0 + h)) / h;
        assert!(
            v_before.distance(v_after) < 0.05 * v_before.length().max(1.0),
            "{v_before} vs {v_after}"
        );
        assert!(at(-1.0).abs_diff_eq(at(3.0), 1e-4) && at(9.5).abs_diff_eq(at(1.5), 1e-3));
    }

    #[test]
    fn anim_wrap_modes_and_degenerate_paths() {
        let mut p = square_loop();
        p.wrap = Wrap::PingPong;
        for x in [0.25f32, 1.0, 2.5] {
            assert!(sample_path(&p, 4.0 + x)
                .0
                .abs_diff_eq(sample_path(&p, 4.0 - x).0, 1e-3));
        }
        p.wrap = Wrap::Clamp;
        assert_eq!(sample_path(&p, 100.0).0, Vec3::ZERO);
        assert_eq!(sample_path(&p, -5.0).0, Vec3::ZERO);
        assert_eq!(sample_path(&p, f32::NAN).0, Vec3::ZERO);
        let single = path(Wrap::Loop, &[(0.0, [1.0, 2.0, 3.0])]);
        for t in [0.0, 1.0, 1e6] {
            assert_eq!(sample_path(&single, t).0, Vec3::new(1.0, 2.0, 3.0));
        }
        let empty = PathDesc {
            keys: vec![],
            wrap: Wrap::Loop,
        };
        assert_eq!(sample_path(&empty, 1.0), (Vec3::ZERO, None));
        // Mixed targets → no target.
        let mut mixed = square_loop();
        mixed.keys[2].target = None;
        assert_eq!(sample_path(&mixed, 0.5).1, None);
    }

    #[test]
    fn anim_builtin_camera_and_light_move() {
        for name in crate::scene::descriptor::builtin_names() {
            let d = SceneDescriptor::resolve(name).unwrap();
            let clock = FrameClock::new(&d);
            let (f0, f30) = (clock.frame(0), clock.frame(30));
            // Barczak's rooms keep camera and light still, as the thesis measured fixed views
            // (only their movers move); every other scene moves both, as Laine measured, but
            // a `-still-light` variant, which holds its light to measure the flicker the
            // movers and the camera alone cause.
            let still = name.starts_with("barczak-");
            let light_still = still || name.ends_with("-still-light");
            assert_eq!(
                f0.camera.position.distance(f30.camera.position) > 1e-3,
                !still,
                "{name}: camera"
            );
            assert_eq!(
                f0.light.position.distance(f30.light.position) > 1e-3,
                !light_still,
                "{name}: light"
            );
            for (a, b) in f0.movers.iter().zip(&f30.movers) {
                assert!(!a.abs_diff_eq(*b, 1e-4), "{name}: a mover does not move");
            }
            assert_eq!(f0.movers.len(), d.movers.len());
            for f in [&f0, &f30] {
                assert!((f.camera.forward().length() - 1.0).abs() < 1e-5);
                assert!((f.light.direction.length() - 1.0).abs() < 1e-5);
                assert_eq!(f.light.power, Vec3::from(d.light.power));
            }
        }
    }

    #[test]
    fn anim_poses() {
        let mut d = SceneDescriptor::resolve("cornell-bunny").unwrap();
        let f = FrameClock::new(&d).frame(0);
        assert_eq!(f.camera.up, Vec3::Y);
        assert!((f.camera.fov_y_rad - 39.3077f32.to_radians()).abs() < 1e-6);
        // The spot points at its target.
        let k = &d.light.path.keys[0];
        let want = (Vec3::from(k.target.unwrap()) - Vec3::from(k.position)).normalize();
        assert!(f.light.direction.abs_diff_eq(want, 1e-4));
        // The mover's +Z axis faces its target horizontally; the transform is rigid.
        let k = &d.movers[0].path.keys[0];
        let (pos, target) = (Vec3::from(k.position), Vec3::from(k.target.unwrap()));
        let m = f.movers[0];
        assert!(m.transform_point3(Vec3::ZERO).abs_diff_eq(pos, 1e-3));
        let z = m.transform_vector3(Vec3::Z);
        let horizontal = Vec3::new(target.x - pos.x, 0.0, target.z - pos.z).normalize();
        assert!(z.abs_diff_eq(horizontal, 1e-4), "{z} vs {horizontal}");
        // Looking straight down: up becomes +Z.
        for k in &mut d.camera.path.keys {
            k.target = Some([k.position[0], k.position[1] - 100.0, k.position[2]]);
        }
        assert_eq!(FrameClock::new(&d).frame(3).camera.up, Vec3::Z);
        // An omni light without targets points down.
        d.light.kind = LightKind::Omni;
        for k in &mut d.light.path.keys {
            k.target = None;
        }
        assert_eq!(FrameClock::new(&d).frame(3).light.direction, Vec3::NEG_Y);
    }
}
