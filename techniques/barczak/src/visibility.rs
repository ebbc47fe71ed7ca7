//! Visibility determination (Barczak 2006 §4.3.1): for a receiver and a point light, which
//! blockers can cast a shadow on it, and whether the light is unblocked, partially blocked or
//! fully blocked there.
//!
//! Reads: the receiver (a planar rectangular patch, or a complex object's bounding sphere), the
//! light's position and normal, and the blockers (convex polygons for simple ones, bounding
//! spheres for complex ones), all in world space.
//! Writes: per patch-tree node, the light's [`LightState`] and the blockers that reach into its
//! occlusion pyramid, each partial or full ([`NodeVisibility`]), which is what the light maps,
//! the shadow-map subtraction and the movers' visibility database consume.
//!
//! The **occlusion pyramid** of a patch and a light joins the light to the patch's four
//! corners: it is exactly the union of the segments from the light to the patch's points, so a
//! blocker outside it shadows no point of the patch. For a complex receiver the pyramid is
//! widened around its bounding sphere: four planes through the light tangent to the sphere,
//! closed beyond it.
//!
//! * A **polygon** blocker (convex, planar) is clipped by the pyramid's planes: nothing left
//!   means it blocks nothing. It blocks *everything* when the pyramid's four edges all pass
//!   through it before they reach the receiver: the pyramid's cross-section in the polygon's
//!   plane is then the hull of those four crossings, inside the convex polygon, so every
//!   segment from the light to the receiver crosses it.
//! * A **chart** blocker (a mesh's planar chart whose triangles leave gaps in their convex
//!   hull) reaches in as its hull does, and is then partial: the hull cannot prove that every
//!   ray meets a triangle.
//! * A **sphere** blocker (a complex object's bounds) reaches into the pyramid when its centre
//!   is closer to the pyramid (a convex solid: the nearest point of its faces, or zero inside)
//!   than its radius; it is then taken as partial (a bound cannot prove full occlusion).
//!
//! A light behind the patch's plane, or whose emission hemisphere does not reach the patch,
//! does not light it at all ([`LightState::Behind`]).
//!
//! **Hierarchy**: a patch is split into 2 × 2 sub-patches up to `levels` times. A node is tested
//! only against the blockers that were partial on its parent (a blocker missing the parent's
//! pyramid misses its children's, which lie inside it); a node that comes out unblocked or
//! fully blocked ends the descent and its state holds for every node below it. The result is
//! the same as testing every leaf against every blocker (tested).
//!
//! Tolerance ([`Tolerance`]): a polygon counts when what is left of it after clipping covers at
//! least 10⁻⁶ of the (whole) patch's pyramid's solid angle as seen from the light, so polygons
//! that only touch the pyramid (a wall meeting the floor along the patch's edge, the surface
//! the light sits on) do not count, at any distance from the light; the far plane is moved
//! 10⁻⁴ of the pyramid's size towards the light, so polygons lying in the receiver's plane do
//! not count either. Sub-patches use their whole patch's tolerance, so a blocker that misses a
//! node misses its children.

use glam::Vec3;

/// What one blocker does to the rays between a receiver and a light.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Occlusion {
    /// Blocks some rays (or, for a bounding sphere, may).
    Partial,
    /// Blocks every ray.
    Full,
}

/// A light's state over a receiver node.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LightState {
    /// No blocker reaches the occlusion pyramid: no shadow-map access needed.
    Unblocked,
    /// Some blocker reaches into it, none blocks everything: the shadow map decides per pixel.
    Partial,
    /// One blocker blocks every ray: the light adds nothing here.
    Blocked,
    /// The light is behind the receiver (or faces away from it): it adds nothing here.
    Behind,
}

/// A blocker's shape.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A convex planar polygon (a wall, a box face, a table top), vertices in order.
    Polygon(Vec<Vec3>),
    /// A complex object's bounding sphere.
    Sphere { center: Vec3, radius: f32 },
    /// A planar chart of a mesh (`gibench_harness::scene::ChartSurface`) whose triangles do
    /// not fill their convex `hull`: the hull decides what reaches into a pyramid, as a
    /// polygon's outline does, but it blocks only partially (the triangles may leave gaps);
    /// a ray meets the `triangles`.
    Chart {
        hull: Vec<Vec3>,
        triangles: Vec<[Vec3; 3]>,
    },
}

impl Shape {
    /// Every point of the shape's definition, to move it rigidly.
    pub fn points_mut(&mut self) -> Box<dyn Iterator<Item = &mut Vec3> + '_> {
        match self {
            Shape::Polygon(v) => Box::new(v.iter_mut()),
            Shape::Sphere { center, .. } => Box::new(std::iter::once(center)),
            Shape::Chart { hull, triangles } => {
                Box::new(hull.iter_mut().chain(triangles.iter_mut().flatten()))
            }
        }
    }
}

/// A shadow caster: its shape and the object it belongs to (an object never blocks itself).
#[derive(Clone, Debug, PartialEq)]
pub struct Blocker {
    pub object: u32,
    pub shape: Shape,
}

/// A plane, inside where `n·x + d ≥ 0`.
#[derive(Clone, Copy, Debug)]
struct Plane {
    n: Vec3,
    d: f32,
    /// `|n|` per axis: how far a box's corners reach from its centre along `n`, per half-extent.
    abs_n: Vec3,
}

impl Plane {
    /// Through `p` with `n` pointing inside.
    fn through(p: Vec3, n: Vec3) -> Plane {
        Plane {
            n,
            d: -n.dot(p),
            abs_n: n.abs(),
        }
    }
    fn distance(&self, x: Vec3) -> f32 {
        self.n.dot(x) + self.d
    }
}

/// The occlusion pyramid of a receiver and a light (see the module docs).
#[derive(Clone, Debug)]
pub struct Pyramid {
    apex: Vec3,
    /// Where the four edges end for the Full test: the patch's corners, or, for a sphere, the
    /// corners of the cross-section in front of it.
    ends: [Vec3; 4],
    /// The far face's corners (the patch's; for a sphere, the cross-section beyond it).
    far: [Vec3; 4],
    /// Four side planes and the far plane, unit normals pointing inside.
    planes: [Plane; 5],
    tolerance: Tolerance,
}

/// What counts as touching (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// Distances below this count as touching (the far plane, the Full test's ends).
    pub eps: f32,
    /// A clipped polygon smaller than this solid angle at the light (sr) does not count.
    pub min_solid_angle: f32,
}

impl Tolerance {
    /// The tolerance of the pyramid from `light` to a patch with `corners`.
    pub fn of_patch(light: Vec3, corners: &[Vec3; 4]) -> Tolerance {
        let size = corners
            .iter()
            .map(|c| (*c - light).length())
            .fold(0f32, f32::max);
        Tolerance {
            eps: 1e-4 * size,
            min_solid_angle: 1e-6 * solid_angle(light, corners),
        }
    }
}

impl Pyramid {
    /// The pyramid from `light` to the patch with corners `corners` (in order around it) and
    /// front normal `normal`, with `tolerance` (the whole patch's for a sub-patch); `None`
    /// when the light is not in front of the patch.
    pub fn to_patch(
        light: Vec3,
        corners: [Vec3; 4],
        normal: Vec3,
        tolerance: Tolerance,
    ) -> Option<Pyramid> {
        let normal = normal.normalize();
        let eps = tolerance.eps;
        let centre = corners.iter().copied().sum::<Vec3>() / 4.0;
        if normal.dot(light - centre) <= eps
            || corners.iter().any(|c| normal.dot(light - *c) <= eps)
        {
            return None;
        }
        let mut planes = [Plane::through(corners[0], normal); 5];
        for i in 0..4 {
            let (a, b) = (corners[i] - light, corners[(i + 1) % 4] - light);
            let mut n = a.cross(b).normalize_or_zero();
            if n.dot(centre - light) < 0.0 {
                n = -n;
            }
            planes[i] = Plane::through(light, n);
        }
        Some(Pyramid {
            apex: light,
            ends: corners,
            far: corners,
            planes,
            tolerance,
        })
    }

    /// The pyramid from `light` enclosing the sphere (`center`, `radius`), closed just beyond
    /// it; `None` when the light is inside the sphere.
    pub fn to_sphere(light: Vec3, center: Vec3, radius: f32) -> Option<Pyramid> {
        let axis = center - light;
        let dist = axis.length();
        if dist <= radius * (1.0 + 1e-5) {
            return None;
        }
        let a = axis / dist;
        let (sin, cos) = (radius / dist, (1.0 - (radius / dist).powi(2)).sqrt());
        let u = a.any_orthonormal_vector();
        let v = a.cross(u);
        // Tangent planes through the light: outward normal cos·w − sin·a for w = ±u, ±v.
        let sides = [u, v, -u, -v];
        let mut planes = [Plane::through(center + a * radius, -a); 5];
        for (i, w) in sides.iter().enumerate() {
            planes[i] = Plane::through(light, -(cos * *w - sin * a));
        }
        // The edges (where neighbouring side planes meet) cut at the sphere's near side.
        let near = dist - radius;
        let tan = sin / cos;
        let edges = [(u, v), (v, -u), (-u, -v), (-v, u)].map(|(p, q)| a + tan * (p + q));
        let ends = edges.map(|e| light + near * e);
        Some(Pyramid {
            apex: light,
            ends,
            far: edges.map(|e| light + (dist + radius) * e),
            planes,
            tolerance: Tolerance {
                eps: 1e-4 * (dist + radius),
                min_solid_angle: 1e-6 * solid_angle(light, &ends),
            },
        })
    }

    /// What `shape` does to the rays inside the pyramid: `None` when it stays outside.
    pub fn test(&self, shape: &Shape) -> Option<Occlusion> {
        match shape {
            Shape::Sphere { center, radius } => {
                (self.distance(*center) < *radius).then_some(Occlusion::Partial)
            }
            Shape::Polygon(vertices) => {
                if !self.clips_to_something(vertices) {
                    return None;
                }
                Some(if self.edges_all_cross(vertices) {
                    Occlusion::Full
                } else {
                    Occlusion::Partial
                })
            }
            Shape::Chart { hull, .. } => {
                self.clips_to_something(hull).then_some(Occlusion::Partial)
            }
        }
    }

    /// The distance from `x` to the pyramid (zero inside).
    fn distance(&self, x: Vec3) -> f32 {
        if self.planes.iter().all(|p| p.distance(x) >= 0.0) {
            return 0.0;
        }
        let f = self.far;
        let mut best = f32::MAX;
        for i in 0..4 {
            best = best.min(triangle_distance(x, self.apex, f[i], f[(i + 1) % 4]));
        }
        best.min(triangle_distance(x, f[0], f[1], f[2]))
            .min(triangle_distance(x, f[0], f[2], f[3]))
    }

    /// Whether what is left of the convex polygon after clipping by the pyramid (its far plane
    /// moved `eps` towards the light) covers a share of the pyramid's solid angle.
    fn clips_to_something(&self, vertices: &[Vec3]) -> bool {
        let shift = |k: usize| if k == 4 { self.tolerance.eps } else { 0.0 };
        // Wholly outside one plane: nothing is left (the common case, decided without
        // clipping); wholly inside a plane: that plane clips nothing.
        let mut cutting = 0u32;
        for (k, plane) in self.planes.iter().enumerate() {
            let (mut any_in, mut all_in) = (false, true);
            for v in vertices {
                let d = plane.distance(*v) - shift(k);
                any_in |= d >= 0.0;
                all_in &= d >= 0.0;
            }
            if !any_in {
                return false;
            }
            cutting |= (!all_in as u32) << k;
        }
        if cutting == 0 {
            return solid_angle(self.apex, vertices) > self.tolerance.min_solid_angle;
        }
        thread_local! {
            /// The clipped polygon and the next one (kept: a database build clips millions).
            static SCRATCH: std::cell::RefCell<(Vec<Vec3>, Vec<Vec3>)> = Default::default();
        }
        SCRATCH.with_borrow_mut(|(poly, next)| {
            poly.clear();
            poly.extend_from_slice(vertices);
            for (k, plane) in self.planes.iter().enumerate() {
                if cutting & (1 << k) == 0 {
                    continue;
                }
                let shift = shift(k);
                next.clear();
                // Each edge p → q in turn, starting with the closing one.
                let mut p = poly[poly.len() - 1];
                let mut dp = plane.distance(p) - shift;
                for &q in poly.iter() {
                    let dq = plane.distance(q) - shift;
                    if (dp >= 0.0) != (dq >= 0.0) {
                        next.push(p + (q - p) * (dp / (dp - dq)));
                    }
                    if dq >= 0.0 {
                        next.push(q);
                    }
                    (p, dp) = (q, dq);
                }
                std::mem::swap(poly, next);
                if poly.len() < 3 {
                    return false;
                }
            }
            solid_angle(self.apex, poly) > self.tolerance.min_solid_angle
        })
    }

    /// Whether all four edges of the pyramid pass through the polygon's interior strictly
    /// between the light and their ends.
    fn edges_all_cross(&self, vertices: &[Vec3]) -> bool {
        if vertices.len() < 3 {
            return false;
        }
        let n = polygon_normal(vertices);
        if n == Vec3::ZERO {
            return false;
        }
        self.ends
            .iter()
            .all(|end| segment_crosses_polygon(self.apex, *end, vertices, n, self.tolerance.eps))
    }
}

/// The solid angle the convex polygon `vertices` subtends at `eye` (a fan of spherical
/// triangles, Van Oosterom and Strackee's formula); points at the eye add nothing.
fn solid_angle(eye: Vec3, vertices: &[Vec3]) -> f32 {
    let mut dirs = vertices
        .iter()
        .map(|v| (*v - eye).normalize_or_zero())
        .filter(|d| *d != Vec3::ZERO);
    let Some(a) = dirs.next() else {
        return 0.0;
    };
    let Some(mut b) = dirs.next() else {
        return 0.0;
    };
    let mut total = 0.0;
    for c in dirs {
        let num = a.dot(b.cross(c)).abs();
        let den = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
        total += 2.0 * num.atan2(den);
        b = c;
    }
    total
}

/// The distance from `p` to the triangle (a, b, c): its nearest point by the triangle's
/// Voronoi regions (vertices, edges, face).
fn triangle_distance(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f32 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.length();
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return bp.length();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (p - (a + ab * (d1 / (d1 - d3)))).length();
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return cp.length();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (p - (a + ac * (d2 / (d2 - d6)))).length();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (p - (b + (c - b) * t)).length();
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (p - (a + ab * v + ac * w)).length()
}

/// The unit normal of a planar polygon (Newell's method); zero when degenerate.
fn polygon_normal(vertices: &[Vec3]) -> Vec3 {
    let mut n = Vec3::ZERO;
    for i in 0..vertices.len() {
        let (p, q) = (vertices[i], vertices[(i + 1) % vertices.len()]);
        n += (p - q).cross(p + q) * 0.5;
    }
    n.normalize_or_zero()
}

/// Whether the segment a→b crosses the convex polygon (unit normal `n`) at least `eps` inside
/// its edges and `eps` away from both ends.
fn segment_crosses_polygon(a: Vec3, b: Vec3, vertices: &[Vec3], n: Vec3, eps: f32) -> bool {
    let (da, db) = (n.dot(a - vertices[0]), n.dot(b - vertices[0]));
    if (da > 0.0) == (db > 0.0) || da == db {
        return false;
    }
    let t = da / (da - db);
    let len = (b - a).length();
    if t * len <= eps || (1.0 - t) * len <= eps {
        return false;
    }
    let x = a + (b - a) * t;
    // Inside every edge, by at least eps (the polygon's winding taken from n).
    (0..vertices.len()).all(|i| {
        let (p, q) = (vertices[i], vertices[(i + 1) % vertices.len()]);
        let inward = n.cross(q - p).normalize_or_zero();
        inward.dot(x - p) >= eps
    })
}

/// Whether the segment a→b (ends excluded by `eps`) meets `shape`: the brute-force test the
/// tests compare with, and what a ray cast would say.
pub fn segment_hits(a: Vec3, b: Vec3, shape: &Shape, eps: f32) -> bool {
    match shape {
        Shape::Sphere { center, radius } => {
            let d = b - a;
            let t = ((*center - a).dot(d) / d.length_squared()).clamp(0.0, 1.0);
            (a + d * t - *center).length() < *radius
        }
        Shape::Polygon(vertices) => {
            let n = polygon_normal(vertices);
            n != Vec3::ZERO && segment_crosses_polygon(a, b, vertices, n, eps)
        }
        Shape::Chart { triangles, .. } => triangles.iter().any(|t| {
            let n = polygon_normal(t);
            n != Vec3::ZERO && segment_crosses_polygon(a, b, t, n, eps)
        }),
    }
}

/// A light: a point with the normal of the surface it sits on (it emits into the hemisphere
/// around it; `None` for an omnidirectional one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    pub position: Vec3,
    pub normal: Option<Vec3>,
}

/// A planar rectangular patch split into 2 × 2 sub-patches down to `levels` (node 0 is the
/// whole patch; children follow their parent).
#[derive(Clone, Debug)]
pub struct PatchTree {
    pub object: u32,
    pub normal: Vec3,
    pub nodes: Vec<PatchNode>,
    /// The triangles the patch stands for where they cover only part of its rectangle (a
    /// chart); empty: the rectangle is the surface.
    pub surface: Vec<[Vec3; 3]>,
}

/// One node of a [`PatchTree`].
#[derive(Clone, Debug)]
pub struct PatchNode {
    /// Corners in order around the patch.
    pub corners: [Vec3; 4],
    pub level: u32,
    /// The four sub-patches' node indices, `None` for a leaf.
    pub children: Option<[u32; 4]>,
}

impl PatchTree {
    /// The patch with `corners` (in order; `normal` its front side) of `object`, split
    /// `levels` times.
    pub fn new(object: u32, corners: [Vec3; 4], normal: Vec3, levels: u32) -> PatchTree {
        let mut tree = PatchTree {
            object,
            normal: normal.normalize(),
            nodes: vec![PatchNode {
                corners,
                level: 0,
                children: None,
            }],
            surface: Vec::new(),
        };
        let mut i = 0;
        while i < tree.nodes.len() {
            let node = tree.nodes[i].clone();
            if node.level < levels {
                let [a, b, c, d] = node.corners;
                let at = |s: f32, t: f32| a.lerp(b, s).lerp(d.lerp(c, s), t);
                let first = tree.nodes.len() as u32;
                for (s, t) in [(0.0, 0.0), (0.5, 0.0), (0.5, 0.5), (0.0, 0.5)] {
                    tree.nodes.push(PatchNode {
                        corners: [
                            at(s, t),
                            at(s + 0.5, t),
                            at(s + 0.5, t + 0.5),
                            at(s, t + 0.5),
                        ],
                        level: node.level + 1,
                        children: None,
                    });
                }
                tree.nodes[i].children = Some([first, first + 1, first + 2, first + 3]);
            }
            i += 1;
        }
        tree
    }

    /// The tree standing for `triangles` (see [`PatchTree::surface`]).
    pub fn with_surface(mut self, triangles: Vec<[Vec3; 3]>) -> PatchTree {
        self.surface = triangles;
        self
    }

    /// The tolerance every node's pyramid to `light` uses: the whole patch's.
    pub fn tolerance(&self, light: &PointLight) -> Tolerance {
        Tolerance::of_patch(light.position, &self.nodes[0].corners)
    }

    /// The leaves' node indices.
    pub fn leaves(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.nodes.len()).filter(|&i| self.nodes[i].children.is_none())
    }
}

/// A light's visibility over one node.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeVisibility {
    pub state: LightState,
    /// The blockers (indices into the blocker list) reaching into this node's pyramid and what
    /// each does; empty for nodes whose state was inherited without a test.
    pub blockers: Vec<(u32, Occlusion)>,
    /// Whether this node was tested (false: it inherited its parent's state).
    pub tested: bool,
}

/// Where a light's rays to a receiver node run: nowhere (the light is behind it or faces away),
/// everywhere (a light inside a complex object's bounds: every blocker may shadow it), or
/// through an occlusion pyramid.
// Built on the stack for every node and light of a database (millions): boxing the pyramid
// would allocate each time.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub enum Reach {
    Behind,
    Everything,
    Pyramid(Pyramid),
}

impl Reach {
    /// To the patch node with `corners` (front normal `normal`), with the whole patch's
    /// `tolerance`.
    pub fn patch(
        light: &PointLight,
        corners: [Vec3; 4],
        normal: Vec3,
        tolerance: Tolerance,
    ) -> Reach {
        if misses(light, &corners) {
            return Reach::Behind;
        }
        match Pyramid::to_patch(light.position, corners, normal, tolerance) {
            Some(p) => Reach::Pyramid(p),
            None => Reach::Behind,
        }
    }

    /// To a complex object with bounding sphere (`center`, `radius`).
    pub fn object(light: &PointLight, center: Vec3, radius: f32) -> Reach {
        if light
            .normal
            .is_some_and(|ln| ln.dot(center - light.position) <= -radius)
        {
            return Reach::Behind;
        }
        match Pyramid::to_sphere(light.position, center, radius) {
            Some(p) => Reach::Pyramid(p),
            None => Reach::Everything,
        }
    }

    /// From `light` to anywhere in the sphere (`center`, `radius`), the light's hemisphere
    /// left out: a pyramid holding every segment from the light to the sphere's points.
    pub fn around(light: &PointLight, center: Vec3, radius: f32) -> Reach {
        match Pyramid::to_sphere(light.position, center, radius) {
            Some(p) => Reach::Pyramid(p),
            None => Reach::Everything,
        }
    }

    /// Whether nothing inside the axis-aligned box `lo`..`hi` can reach in: the box lies
    /// outside one of the pyramid's planes (or the light is behind).
    pub fn rules_out(&self, lo: Vec3, hi: Vec3) -> bool {
        self.cull(lo, hi, u32::MAX).is_none()
    }

    /// [`Reach::rules_out`] for a search down a hierarchy of boxes: only the planes in `mask`
    /// (bit k: plane k) are tested; `None` when the box lies outside one of them, else `mask`
    /// without the planes the box lies wholly inside (every box inside it does too).
    pub fn cull(&self, lo: Vec3, hi: Vec3, mask: u32) -> Option<u32> {
        match self {
            Reach::Behind => None,
            Reach::Everything => Some(0),
            Reach::Pyramid(p) => {
                let (c, e) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
                let mut left = mask;
                for (k, pl) in p.planes.iter().enumerate() {
                    if mask & (1 << k) == 0 {
                        continue;
                    }
                    let (centre, reach) = (pl.distance(c), pl.abs_n.dot(e));
                    if centre + reach < 0.0 {
                        return None;
                    }
                    if centre - reach >= 0.0 {
                        left &= !(1 << k);
                    }
                }
                Some(left & 0b11111)
            }
        }
    }

    /// What `shape` does to these rays.
    pub fn test(&self, shape: &Shape) -> Option<Occlusion> {
        match self {
            Reach::Behind => None,
            Reach::Everything => Some(Occlusion::Partial),
            Reach::Pyramid(p) => p.test(shape),
        }
    }

    /// The light's state over the node, from the blockers reaching in.
    pub fn state(&self, blockers: &[(u32, Occlusion)]) -> LightState {
        if matches!(self, Reach::Behind) {
            LightState::Behind
        } else if blockers.iter().any(|(_, o)| *o == Occlusion::Full) {
            LightState::Blocked
        } else if blockers.is_empty() {
            LightState::Unblocked
        } else {
            LightState::Partial
        }
    }

    /// The node's visibility against `candidates` (indices into `blockers`; `object`'s own
    /// blockers skipped).
    pub fn classify(
        &self,
        object: u32,
        blockers: &[Blocker],
        candidates: impl Iterator<Item = u32>,
    ) -> NodeVisibility {
        let mut list = Vec::new();
        if !matches!(self, Reach::Behind) {
            for b in candidates {
                let blocker = &blockers[b as usize];
                if blocker.object == object {
                    continue;
                }
                if let Some(o) = self.test(&blocker.shape) {
                    list.push((b, o));
                }
            }
        }
        NodeVisibility {
            state: self.state(&list),
            blockers: list,
            tested: true,
        }
    }
}

/// Whether the light's hemisphere misses every corner of the patch.
fn misses(light: &PointLight, corners: &[Vec3; 4]) -> bool {
    light
        .normal
        .is_some_and(|ln| corners.iter().all(|c| ln.dot(*c - light.position) <= 0.0))
}

/// The light's state over one patch node against `candidates` (indices into `blockers`), and
/// the blockers reaching into its pyramid, with the whole patch's `tolerance`.
#[allow(clippy::too_many_arguments)]
pub fn classify_patch(
    corners: [Vec3; 4],
    normal: Vec3,
    object: u32,
    light: &PointLight,
    blockers: &[Blocker],
    candidates: impl Iterator<Item = u32>,
    tolerance: Tolerance,
) -> NodeVisibility {
    Reach::patch(light, corners, normal, tolerance).classify(object, blockers, candidates)
}

/// The light's state over a complex object with bounding sphere (`center`, `radius`).
pub fn classify_object(
    center: Vec3,
    radius: f32,
    object: u32,
    light: &PointLight,
    blockers: &[Blocker],
) -> NodeVisibility {
    Reach::object(light, center, radius).classify(object, blockers, 0..blockers.len() as u32)
}

/// The light's visibility over every node of `tree` by the hierarchical test (see the module
/// docs): per node, in node order.
pub fn determine(
    tree: &PatchTree,
    light: &PointLight,
    blockers: &[Blocker],
) -> Vec<NodeVisibility> {
    let mut out: Vec<Option<NodeVisibility>> = vec![None; tree.nodes.len()];
    let root = &tree.nodes[0];
    let tolerance = tree.tolerance(light);
    out[0] = Some(classify_patch(
        root.corners,
        tree.normal,
        tree.object,
        light,
        blockers,
        0..blockers.len() as u32,
        tolerance,
    ));
    // Nodes are stored parents first, so one pass in order sees every parent before its children.
    for i in 0..tree.nodes.len() {
        let Some(children) = tree.nodes[i].children else {
            continue;
        };
        let parent = out[i].clone().expect("parents come first");
        for c in children {
            let c = c as usize;
            out[c] = Some(if parent.state == LightState::Partial {
                classify_patch(
                    tree.nodes[c].corners,
                    tree.normal,
                    tree.object,
                    light,
                    blockers,
                    parent
                        .blockers
                        .iter()
                        .filter(|(_, o)| *o == Occlusion::Partial)
                        .map(|(b, _)| *b),
                    tolerance,
                )
            } else {
                // Inherited; an unblocked light may still miss this part of the patch.
                let state = if parent.state == LightState::Unblocked
                    && misses(light, &tree.nodes[c].corners)
                {
                    LightState::Behind
                } else {
                    parent.state
                };
                NodeVisibility {
                    state,
                    blockers: Vec::new(),
                    tested: false,
                }
            });
        }
    }
    out.into_iter()
        .map(|v| v.expect("every node visited"))
        .collect()
}
