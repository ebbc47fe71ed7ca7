//! **Octahedral face culling** (Barczak 2006 §4.2.2): "a simple culling test for each shadow map
//! face to determine if any of the four faces does not contain occluders", so that a map is
//! drawn only into the faces that hold some.
//!
//! Reads: the occluders in world space — triangles (static casters, taken once when a technique
//! is prepared, as the thesis transforms its occluders into world space once) and bounding
//! spheres (movers, posed once per frame) — and a VPL with the atlas's lift.
//! Writes: a mask per VPL, bit `f` set when octahedral face `f` (numbered as
//! [`AtlasRasteriser`](super::raster::AtlasRasteriser) numbers them: bit 0 set means the
//! quadrant's x sign is −1, bit 1 its y sign) may receive a fragment.
//!
//! The test is exact in one direction: a face whose bit is clear gets no fragment. The
//! rasteriser keeps a fragment of face (sx, sy) where, in the VPL's frame, z, sx·x and sy·y are
//! each at least −10⁻³ |p| (the faces overlap by that sliver). Each of the three regions'
//! complements ({sx·x < −m|p|}, …) is a convex cone, so a triangle whose three corners lie in
//! one of them lies wholly in it and draws nothing into the face; a sphere lies in one when its
//! nearest point to the region does. The test uses m = 2·10⁻³ (twice the rasteriser's margin)
//! so that rounding never clears a face that gets a fragment. A face cleared is left empty
//! (the rasteriser clears the map's block before drawing), which is what drawing it would give.

use glam::Vec3;

use super::atlas::ShadowAtlas;
use crate::cpu::vpl::{frame_from_normal, Vpl};

/// The margin of the test, relative to the distance from the map's centre (see the module docs).
const MARGIN: f32 = 2e-3;

/// Every face of an octahedral map.
pub const ALL_FACES: u8 = 0b1111;

/// The occluders a map may hold (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct Occluders {
    triangles: Vec<[Vec3; 3]>,
    spheres: Vec<(Vec3, f32)>,
}

impl Occluders {
    /// The static occluders: triangles in world space.
    pub fn new(triangles: Vec<[Vec3; 3]>) -> Occluders {
        Occluders {
            triangles,
            spheres: Vec::new(),
        }
    }

    /// Replaces the moving occluders' bounding spheres (centre, radius; world space), keeping
    /// the list's memory.
    pub fn set_spheres(&mut self, spheres: impl IntoIterator<Item = (Vec3, f32)>) {
        self.spheres.clear();
        self.spheres.extend(spheres);
    }

    /// The faces of `vpl`'s octahedral map in `atlas` that may receive a fragment.
    pub fn faces(&self, atlas: &ShadowAtlas, vpl: &Vpl) -> u8 {
        self.faces_at(vpl.position + vpl.normal * atlas.lift, vpl.normal)
    }

    /// The faces of an octahedral map centred at `eye` around `normal` that may receive a
    /// fragment.
    pub fn faces_at(&self, eye: Vec3, normal: Vec3) -> u8 {
        let (t, b) = frame_from_normal(normal);
        let n = normal.normalize_or(Vec3::Z);
        let local = |p: Vec3| {
            let d = p - eye;
            (Vec3::new(d.dot(t), d.dot(b), d.dot(n)), d.length())
        };
        let mut mask = 0u8;
        for tri in &self.triangles {
            // Per region, whether all three corners are outside it: z ≥ −m, x ≥ −m, −x ≥ −m,
            // y ≥ −m, −y ≥ −m.
            let mut outside = [true; 5];
            for &p in tri {
                let (l, len) = local(p);
                let m = -MARGIN * len;
                for (o, v) in outside.iter_mut().zip([l.z, l.x, -l.x, l.y, -l.y]) {
                    *o &= v < m;
                }
            }
            mask |= reached(outside);
            if mask == ALL_FACES {
                return mask;
            }
        }
        for &(c, r) in &self.spheres {
            let (l, len) = local(c);
            // Every point p of the sphere has v(p) ≤ v(c) + r and |p| ≤ |c| + r.
            let m = -MARGIN * (len + r);
            let outside = [l.z, l.x, -l.x, l.y, -l.y].map(|v| v + r < m);
            mask |= reached(outside);
            if mask == ALL_FACES {
                return mask;
            }
        }
        mask
    }
}

/// The faces an occluder may reach, given for each region (z, +x, −x, +y, −y) whether it lies
/// wholly outside it.
fn reached(outside: [bool; 5]) -> u8 {
    if outside[0] {
        return 0;
    }
    let mut mask = 0;
    for f in 0..4u8 {
        let x = if f & 1 == 0 { outside[1] } else { outside[2] };
        let y = if f & 2 == 0 { outside[3] } else { outside[4] };
        if !x && !y {
            mask |= 1 << f;
        }
    }
    mask
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::cpu::reference::Rng;

    fn point(rng: &mut Rng) -> Vec3 {
        Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0
    }

    /// The faces the rasteriser keeps a point `p` in (its fragment test).
    fn faces_of_point(eye: Vec3, normal: Vec3, p: Vec3) -> u8 {
        let (t, b) = frame_from_normal(normal);
        let d = p - eye;
        let l = Vec3::new(d.dot(t), d.dot(b), d.dot(normal));
        let m = -1e-3 * d.length();
        let mut mask = 0;
        for f in 0..4u8 {
            let sx = if f & 1 == 0 { 1.0 } else { -1.0 };
            let sy = if f & 2 == 0 { 1.0 } else { -1.0 };
            if l.z >= m && sx * l.x >= m && sy * l.y >= m {
                mask |= 1 << f;
            }
        }
        mask
    }

    /// No face a triangle's points are drawn into is culled: many random triangles, each
    /// sampled densely (corners, edges and inside).
    #[test]
    fn a_culled_face_gets_no_point_of_any_triangle() {
        let mut rng = Rng::new(7, 0);
        let mut culled = 0;
        for _ in 0..2000 {
            let eye = point(&mut rng) * 0.1;
            let normal = point(&mut rng).normalize_or(Vec3::Z);
            let c = point(&mut rng);
            let tri = [0, 1, 2].map(|_| c + point(&mut rng) * 0.3);
            let occ = Occluders::new(vec![tri]);
            let mask = occ.faces_at(eye, normal);
            culled += 4 - mask.count_ones();
            for i in 0..=20 {
                for j in 0..=(20 - i) {
                    let (u, v) = (i as f32 / 20.0, j as f32 / 20.0);
                    let p = tri[0] + (tri[1] - tri[0]) * u + (tri[2] - tri[0]) * v;
                    let hit = faces_of_point(eye, normal, p);
                    assert_eq!(
                        hit & !mask,
                        0,
                        "{tri:?} from {eye} {normal}: mask {mask:04b}"
                    );
                }
            }
        }
        // The test is not vacuous: most faces of small triangles are culled.
        assert!(culled > 4000, "{culled}");
    }

    /// The same for spheres: points sampled on and in random spheres.
    #[test]
    fn a_culled_face_gets_no_point_of_any_sphere() {
        let mut rng = Rng::new(11, 0);
        let mut culled = 0;
        for _ in 0..2000 {
            let eye = point(&mut rng) * 0.1;
            let normal = point(&mut rng).normalize_or(Vec3::Z);
            let (c, r) = (point(&mut rng), 0.05 + 0.3 * rng.next_f32());
            let mut occ = Occluders::new(Vec::new());
            occ.set_spheres([(c, r)]);
            let mask = occ.faces_at(eye, normal);
            culled += 4 - mask.count_ones();
            for k in 0..300 {
                let d = point(&mut rng).normalize_or(Vec3::X);
                // Half on the surface, half inside.
                let s = if k % 2 == 0 {
                    1.0
                } else {
                    rng.next_f32().cbrt()
                };
                let p = c + d * r * s;
                let hit = faces_of_point(eye, normal, p);
                assert_eq!(hit & !mask, 0, "sphere {c} {r} from {eye}: mask {mask:04b}");
            }
        }
        assert!(culled > 2000, "{culled}");
    }

    /// An occluder in one quadrant of the hemisphere reaches that face only; one behind the map
    /// none; one across the axis two.
    #[test]
    fn faces_by_quadrant() {
        let (t, b) = frame_from_normal(Vec3::Y);
        let at = |x: f32, y: f32, z: f32| t * x + b * y + Vec3::Y * z;
        let tri = |c: Vec3| vec![[c, c + t * 0.01, c + b * 0.01]];
        let faces = |o: Occluders| o.faces_at(Vec3::ZERO, Vec3::Y);
        assert_eq!(faces(Occluders::new(tri(at(0.5, 0.5, 0.5)))), 0b0001);
        assert_eq!(faces(Occluders::new(tri(at(-0.5, 0.5, 0.5)))), 0b0010);
        assert_eq!(faces(Occluders::new(tri(at(0.5, -0.5, 0.5)))), 0b0100);
        assert_eq!(faces(Occluders::new(tri(at(-0.5, -0.5, 0.5)))), 0b1000);
        assert_eq!(faces(Occluders::new(tri(at(0.5, 0.5, -0.5)))), 0);
        let across = vec![[at(-0.5, 0.5, 0.5), at(0.5, 0.5, 0.5), at(0.0, 0.6, 0.5)]];
        assert_eq!(faces(Occluders::new(across)), 0b0011);
    }
}
