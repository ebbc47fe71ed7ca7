//! Charts: the planar patches of a mesh that records none (what Barczak 2006's light maps and
//! visibility culling need on any scene, §4.3).
//!
//! Reads: a [`Mesh`] (positions, indices, per-vertex materials).
//! Writes: [`Chart`]s: sets of edge-connected triangles of one material lying in one plane,
//! each with the smallest rectangle in that plane that holds them (the receiver and its light
//! map), the convex hull of its triangles (its blocker) and whether the triangles fill that
//! hull (then the hull blocks fully where it covers a pyramid; otherwise only partially).
//!
//! * Triangles are joined across an edge when both its end positions are equal (vertices split
//!   for normals or texture seams are joined by position, bit for bit).
//! * A chart grows from its seed (the largest triangle not yet taken, so large flat surfaces
//!   seed their own chart) over edges, taking a neighbour of the same material whose normal is
//!   within [`ChartSettings::max_angle_deg`] of the seed's and whose corners lie within
//!   [`ChartSettings::plane_tolerance`] of the seed's plane (measured against the seed, not the
//!   chart so far, so a chart cannot drift around a curved surface).
//! * Degenerate triangles (no area) belong to no chart.
//! * The rectangle is the minimum-area one over the directions of the hull's edges (one of
//!   them is always a side of the minimum rectangle).

use std::collections::HashMap;

use glam::{Vec2, Vec3};

use super::Mesh;

/// How coplanar triangles must be to share a chart.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChartSettings {
    /// Largest angle between a triangle's normal and its chart seed's, in degrees.
    pub max_angle_deg: f32,
    /// Largest distance of a triangle's corner from its seed's plane, in scene units.
    pub plane_tolerance: f32,
}

impl ChartSettings {
    /// 1° and 10⁻⁵ of the mesh's bounding diagonal: flat within what a light map can show.
    pub fn for_mesh(mesh: &Mesh) -> ChartSettings {
        let (lo, hi) = mesh.bounds();
        ChartSettings {
            max_angle_deg: 1.0,
            plane_tolerance: 1e-5 * (hi - lo).length().max(f32::MIN_POSITIVE),
        }
    }
}

/// One chart (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Chart {
    /// Its triangles (indices into the mesh), seed first.
    pub triangles: Vec<u32>,
    /// The seed's unit normal (the front side).
    pub normal: Vec3,
    pub material: u32,
    /// The smallest rectangle in the chart's plane holding its triangles, counter-clockwise
    /// seen from the front.
    pub rectangle: [Vec3; 4],
    /// The convex hull of its corners in its plane, counter-clockwise seen from the front.
    pub hull: Vec<Vec3>,
    /// Whether the triangles fill the hull (their area is the hull's within 10⁻⁴).
    pub convex: bool,
    /// The triangles' total area.
    pub area: f32,
}

fn key(p: Vec3) -> [u32; 3] {
    [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]
}

/// Twice the signed area of the 2-D triangle (o, a, b).
fn cross2(o: Vec2, a: Vec2, b: Vec2) -> f32 {
    (a - o).perp_dot(b - o)
}

/// The convex hull of `points`, counter-clockwise, without collinear points (Andrew's
/// monotone chain).
pub fn convex_hull(points: &[Vec2]) -> Vec<Vec2> {
    let mut p: Vec<Vec2> = points.to_vec();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let mut hull: Vec<Vec2> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Vec2>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in iter {
            while hull.len() >= start + 2
                && cross2(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    hull
}

/// The signed area of a polygon (positive when counter-clockwise).
pub fn polygon_area(p: &[Vec2]) -> f32 {
    let n = p.len();
    (0..n).map(|i| p[i].perp_dot(p[(i + 1) % n])).sum::<f32>() * 0.5
}

/// The minimum-area rectangle holding the convex polygon `hull` (counter-clockwise): its
/// corners, counter-clockwise.
pub fn min_area_rectangle(hull: &[Vec2]) -> [Vec2; 4] {
    let mut best: Option<(f32, [Vec2; 4])> = None;
    let n = hull.len();
    let directions: Vec<Vec2> = if n < 2 {
        vec![Vec2::X]
    } else {
        (0..n)
            .filter_map(|i| (hull[(i + 1) % n] - hull[i]).try_normalize())
            .collect()
    };
    for u in directions {
        let v = u.perp();
        let (mut lo, mut hi) = (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN));
        for p in hull {
            let q = Vec2::new(p.dot(u), p.dot(v));
            lo = lo.min(q);
            hi = hi.max(q);
        }
        let area = (hi - lo).x * (hi - lo).y;
        if best.as_ref().is_none_or(|(a, _)| area < *a) {
            let at = |x: f32, y: f32| x * u + y * v;
            best = Some((
                area,
                [
                    at(lo.x, lo.y),
                    at(hi.x, lo.y),
                    at(hi.x, hi.y),
                    at(lo.x, hi.y),
                ],
            ));
        }
    }
    best.map(|b| b.1).unwrap_or([Vec2::ZERO; 4])
}

/// The charts of `mesh` (see the module docs), largest seed first.
pub fn charts(mesh: &Mesh, settings: ChartSettings) -> Vec<Chart> {
    let n = mesh.triangle_count();
    let cos_max = settings.max_angle_deg.to_radians().cos();
    let normal_area: Vec<(Vec3, f32)> = (0..n)
        .map(|t| {
            let [a, b, c] = mesh.triangle(t);
            let cross = (b - a).cross(c - a);
            let len = cross.length();
            if len.is_finite() && len > f32::MIN_POSITIVE {
                (cross / len, 0.5 * len)
            } else {
                (Vec3::ZERO, 0.0)
            }
        })
        .collect();
    // Edges by their end positions (unordered) → the triangles on them.
    let mut edges: HashMap<([u32; 3], [u32; 3]), Vec<u32>> = HashMap::with_capacity(3 * n);
    for (t, (_, area)) in normal_area.iter().enumerate() {
        if *area == 0.0 {
            continue;
        }
        let p = mesh.triangle(t);
        for k in 0..3 {
            let (a, b) = (key(p[k]), key(p[(k + 1) % 3]));
            let e = if a <= b { (a, b) } else { (b, a) };
            edges.entry(e).or_default().push(t as u32);
        }
    }
    let mut order: Vec<u32> = (0..n as u32)
        .filter(|t| normal_area[*t as usize].1 > 0.0)
        .collect();
    order.sort_by(|a, b| {
        normal_area[*b as usize]
            .1
            .total_cmp(&normal_area[*a as usize].1)
            .then(a.cmp(b))
    });
    let mut taken = vec![false; n];
    let mut out = Vec::new();
    for seed in order {
        if taken[seed as usize] {
            continue;
        }
        taken[seed as usize] = true;
        let normal = normal_area[seed as usize].0;
        let material = mesh.triangle_material(seed as usize);
        let origin = mesh.triangle(seed as usize)[0];
        let mut triangles = vec![seed];
        let mut next = 0;
        while next < triangles.len() {
            let t = triangles[next] as usize;
            next += 1;
            let p = mesh.triangle(t);
            for k in 0..3 {
                let (a, b) = (key(p[k]), key(p[(k + 1) % 3]));
                let e = if a <= b { (a, b) } else { (b, a) };
                for &o in &edges[&e] {
                    let ou = o as usize;
                    if taken[ou]
                        || mesh.triangle_material(ou) != material
                        || normal_area[ou].0.dot(normal) < cos_max
                        || mesh
                            .triangle(ou)
                            .iter()
                            .any(|q| (*q - origin).dot(normal).abs() > settings.plane_tolerance)
                    {
                        continue;
                    }
                    taken[ou] = true;
                    triangles.push(o);
                }
            }
        }
        out.push(make_chart(
            mesh,
            triangles,
            normal,
            material,
            origin,
            &normal_area,
        ));
    }
    out
}

/// The chart of `triangles` in the plane through `origin` with `normal`.
fn make_chart(
    mesh: &Mesh,
    triangles: Vec<u32>,
    normal: Vec3,
    material: u32,
    origin: Vec3,
    normal_area: &[(Vec3, f32)],
) -> Chart {
    let u = normal.any_orthonormal_vector();
    let v = normal.cross(u);
    let flat = |p: Vec3| Vec2::new((p - origin).dot(u), (p - origin).dot(v));
    let lift = |q: Vec2| origin + q.x * u + q.y * v;
    let points: Vec<Vec2> = triangles
        .iter()
        .flat_map(|t| mesh.triangle(*t as usize))
        .map(flat)
        .collect();
    let hull = convex_hull(&points);
    let area: f32 = triangles.iter().map(|t| normal_area[*t as usize].1).sum();
    let hull_area = polygon_area(&hull);
    let rectangle = min_area_rectangle(&hull).map(lift);
    Chart {
        triangles,
        normal,
        material,
        rectangle,
        convex: hull_area <= area * (1.0 + 1e-4),
        hull: hull.into_iter().map(lift).collect(),
        area,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(tris: &[[Vec3; 3]], materials: &[u32]) -> Mesh {
        let mut m = Mesh::default();
        for (k, t) in tris.iter().enumerate() {
            for p in t {
                m.indices.push(m.positions.len() as u32);
                m.positions.push(*p);
                m.normals.push(Vec3::Z);
                m.uvs.push(Vec2::ZERO);
                m.materials.push(materials[k]);
            }
        }
        m
    }

    fn v(x: f32, y: f32, z: f32) -> Vec3 {
        Vec3::new(x, y, z)
    }

    /// An L of three unit squares (six triangles, vertices not shared: joined by position),
    /// a tilted square beside it and a square of another material on the same plane: three
    /// charts; the L is not convex, its rectangle 2 × 2, its hull five corners.
    #[test]
    fn coplanar_neighbours_of_one_material_make_one_chart() {
        let quad = |x: f32, y: f32, z0: f32, z1: f32| {
            [
                [v(x, y, z0), v(x + 1.0, y, z0), v(x + 1.0, y + 1.0, z1)],
                [v(x, y, z0), v(x + 1.0, y + 1.0, z1), v(x, y + 1.0, z1)],
            ]
        };
        let mut tris = Vec::new();
        let mut mats = Vec::new();
        for (x, y) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)] {
            tris.extend(quad(x, y, 0.0, 0.0));
            mats.extend([0, 0]);
        }
        tris.extend(quad(2.0, 0.0, 0.0, 0.5)); // tilted, sharing the edge x = 2
        mats.extend([0, 0]);
        tris.extend(quad(1.0, 1.0, 0.0, 0.0)); // completes the square, other material
        mats.extend([1, 1]);
        let m = mesh(&tris, &mats);
        let charts = charts(&m, ChartSettings::for_mesh(&m));
        assert_eq!(charts.len(), 3, "{charts:?}");
        let l = charts.iter().find(|c| c.triangles.len() == 6).unwrap();
        assert!(!l.convex);
        assert!((l.area - 3.0).abs() < 1e-5);
        assert_eq!(l.hull.len(), 5, "{:?}", l.hull);
        assert!(l.normal.abs_diff_eq(Vec3::Z, 1e-6));
        let r = l.rectangle;
        assert!(((r[1] - r[0]).length() * (r[3] - r[0]).length() - 4.0).abs() < 1e-4);
        // Counter-clockwise seen from +z.
        assert!((r[1] - r[0]).cross(r[2] - r[1]).z > 0.0);
        let other = charts.iter().find(|c| c.material == 1).unwrap();
        assert!(other.convex && other.triangles.len() == 2);
        let tilted = charts
            .iter()
            .find(|c| c.material == 0 && c.triangles.len() == 2)
            .unwrap();
        assert!(tilted.normal.z < 0.95);
    }

    /// Every non-degenerate triangle is in exactly one chart; degenerate ones in none; every
    /// chart's triangles lie inside its rectangle and hull (random fans of coplanar triangles
    /// in random planes, some bent out of plane).
    #[test]
    fn charts_partition_the_triangles_and_hold_them() {
        let mut rng = crate::rng::SplitMix64::from_state(0x9e3779b97f4a7c15);
        let mut rnd = move || rng.next_f32();
        for round in 0..20 {
            let mut tris = Vec::new();
            for _ in 0..5 {
                let n = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize();
                let u = n.any_orthonormal_vector();
                let w = n.cross(u);
                let c = Vec3::new(rnd(), rnd(), rnd()) * 10.0;
                let k = 3 + (rnd() * 6.0) as usize;
                let rim: Vec<Vec3> = (0..k)
                    .map(|i| {
                        let a = i as f32 / k as f32 * std::f32::consts::TAU;
                        c + (1.0 + rnd()) * (a.cos() * u + a.sin() * w)
                    })
                    .collect();
                for i in 0..k {
                    let bent = if rnd() < 0.2 { n * 0.3 } else { Vec3::ZERO };
                    tris.push([c + bent, rim[i], rim[(i + 1) % k]]);
                }
            }
            tris.push([v(0.0, 0.0, 0.0), v(1.0, 1.0, 1.0), v(2.0, 2.0, 2.0)]);
            let m = mesh(&tris, &vec![0; tris.len()]);
            let charts = charts(&m, ChartSettings::for_mesh(&m));
            let mut seen = vec![0; tris.len()];
            for c in &charts {
                let corners = c.rectangle;
                for t in &c.triangles {
                    seen[*t as usize] += 1;
                    for p in m.triangle(*t as usize) {
                        for i in 0..4 {
                            let (a, b) = (corners[i], corners[(i + 1) % 4]);
                            let inside = (b - a).cross(p - a).dot(c.normal);
                            assert!(inside > -1e-3, "round {round}: outside the rectangle");
                        }
                        let h = &c.hull;
                        for i in 0..h.len() {
                            let (a, b) = (h[i], h[(i + 1) % h.len()]);
                            assert!((b - a).cross(p - a).dot(c.normal) > -1e-3);
                        }
                    }
                }
            }
            let last = tris.len() - 1;
            assert_eq!(seen[last], 0, "the degenerate triangle is in no chart");
            assert!(
                seen[..last].iter().all(|s| *s == 1),
                "round {round}: {seen:?}"
            );
        }
    }

    /// The minimum rectangle of a rotated 3 × 1 rectangle is itself (area 3), not its
    /// axis-aligned box.
    #[test]
    fn the_rectangle_is_the_smallest() {
        let (c, s) = (0.6f32, 0.8f32);
        let rot = |x: f32, y: f32| Vec2::new(c * x - s * y, s * x + c * y);
        let pts = [
            rot(0.0, 0.0),
            rot(3.0, 0.0),
            rot(3.0, 1.0),
            rot(0.0, 1.0),
            rot(1.5, 0.5),
        ];
        let hull = convex_hull(&pts);
        assert_eq!(hull.len(), 4);
        let r = min_area_rectangle(&hull);
        let area = (r[1] - r[0]).length() * (r[3] - r[0]).length();
        assert!((area - 3.0).abs() < 1e-4, "{area}");
    }
}
