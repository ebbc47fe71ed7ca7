//! The generated MAZE of the Laine et al. 2007 benchmark: "a simple surrounding scene with a
//! detailed statue". The maze is generated here (a perfect maze on a grid, by a randomised
//! depth-first search with a fixed seed, so it is the same everywhere); the statue is a static
//! instance in the scene descriptor (`statics`, e.g. the Stanford bunny).
//!
//! Units are metres, +Y up. The maze covers [0, cells·cell]² on the floor (y = 0) with walls of
//! `WALL_HEIGHT`, and is open to the sky. The centre cell is left free of inner walls for the
//! statue.

use glam::{Vec2, Vec3};

use super::{Material, Mesh};

/// Cells per side.
pub const CELLS: usize = 8;
/// Edge of one cell (m).
pub const CELL: f32 = 4.0;
/// Wall height (m).
pub const WALL_HEIGHT: f32 = 3.0;
/// Wall thickness (m).
pub const WALL_THICKNESS: f32 = 0.2;

/// Material indices of [`maze`].
pub const FLOOR: u32 = 0;
pub const WALL: u32 = 1;

fn materials() -> Vec<Material> {
    let m = Material::plain;
    vec![
        m("floor", Vec3::new(0.55, 0.5, 0.45)),
        m("wall", Vec3::new(0.75, 0.75, 0.72)),
    ]
}

/// A quad (corners counter-clockwise seen from the side `normal` points to), split into an
/// nu×nv grid when `cell` is given.
pub(crate) fn quad(mesh: &mut Mesh, c: [Vec3; 4], normal: Vec3, material: u32, cell: Option<f32>) {
    let (nu, nv) = match cell {
        Some(s) => (
            (((c[1] - c[0]).length() / s).round() as usize).max(1),
            (((c[3] - c[0]).length() / s).round() as usize).max(1),
        ),
        None => (1, 1),
    };
    let base = mesh.positions.len() as u32;
    for j in 0..=nv {
        for i in 0..=nu {
            let (u, v) = (i as f32 / nu as f32, j as f32 / nv as f32);
            let p = c[0].lerp(c[1], u).lerp(c[3].lerp(c[2], u), v);
            mesh.positions.push(p);
            mesh.normals.push(normal);
            mesh.uvs.push(Vec2::new(u, v));
            mesh.materials.push(material);
        }
    }
    let row = nu as u32 + 1;
    for j in 0..nv as u32 {
        for i in 0..nu as u32 {
            let a = base + j * row + i;
            mesh.indices
                .extend([a, a + 1, a + row + 1, a, a + row + 1, a + row]);
        }
    }
}

/// An axis-aligned wall box from `lo` to `hi` (top and four sides; it stands on the floor).
fn wall(mesh: &mut Mesh, lo: Vec3, hi: Vec3, cell: Option<f32>) {
    let (x0, y0, z0, x1, y1, z1) = (lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
    let v = Vec3::new;
    quad(
        mesh,
        [v(x0, y1, z0), v(x0, y1, z1), v(x1, y1, z1), v(x1, y1, z0)],
        Vec3::Y,
        WALL,
        cell,
    );
    quad(
        mesh,
        [v(x1, y0, z0), v(x0, y0, z0), v(x0, y1, z0), v(x1, y1, z0)],
        Vec3::NEG_Z,
        WALL,
        cell,
    );
    quad(
        mesh,
        [v(x0, y0, z1), v(x1, y0, z1), v(x1, y1, z1), v(x0, y1, z1)],
        Vec3::Z,
        WALL,
        cell,
    );
    quad(
        mesh,
        [v(x0, y0, z0), v(x0, y0, z1), v(x0, y1, z1), v(x0, y1, z0)],
        Vec3::NEG_X,
        WALL,
        cell,
    );
    quad(
        mesh,
        [v(x1, y0, z1), v(x1, y0, z0), v(x1, y1, z0), v(x1, y1, z1)],
        Vec3::X,
        WALL,
        cell,
    );
}

/// Which inner walls stand: `east[i][j]` between cells (i, j) and (i + 1, j), `south[i][j]`
/// between (i, j) and (i, j + 1). A randomised depth-first search from cell (0, 0) with a fixed
/// linear congruential generator carves a perfect maze; then the walls around the centre are
/// opened for the statue.
fn carve() -> (Vec<Vec<bool>>, Vec<Vec<bool>>) {
    let n = CELLS;
    let mut east = vec![vec![true; n]; n];
    let mut south = vec![vec![true; n]; n];
    let mut seen = vec![vec![false; n]; n];
    let mut state: u64 = 0x2007_1aa1;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 33) as usize
    };
    let mut stack = vec![(0usize, 0usize)];
    seen[0][0] = true;
    while let Some(&(i, j)) = stack.last() {
        let mut options = Vec::new();
        if i > 0 && !seen[i - 1][j] {
            options.push((i - 1, j));
        }
        if i + 1 < n && !seen[i + 1][j] {
            options.push((i + 1, j));
        }
        if j > 0 && !seen[i][j - 1] {
            options.push((i, j - 1));
        }
        if j + 1 < n && !seen[i][j + 1] {
            options.push((i, j + 1));
        }
        if options.is_empty() {
            stack.pop();
            continue;
        }
        let (a, b) = options[next() % options.len()];
        match (a as isize - i as isize, b as isize - j as isize) {
            (1, 0) => east[i][j] = false,
            (-1, 0) => east[a][j] = false,
            (0, 1) => south[i][j] = false,
            _ => south[i][b] = false,
        }
        seen[a][b] = true;
        stack.push((a, b));
    }
    // An open 2x2 hall in the middle for the statue.
    let c = n / 2 - 1;
    east[c][c] = false;
    east[c][c + 1] = false;
    south[c][c] = false;
    south[c + 1][c] = false;
    (east, south)
}

/// The maze's floor and walls, with `tessellate` splitting every quad into cells of about that
/// edge length (for paraboloid shadow maps).
pub fn maze(tessellate: Option<f32>) -> (Mesh, Vec<Material>) {
    let n = CELLS;
    let size = n as f32 * CELL;
    let (h, t) = (WALL_HEIGHT, WALL_THICKNESS / 2.0);
    let mut mesh = Mesh::default();
    let v = Vec3::new;
    quad(
        &mut mesh,
        [
            v(0.0, 0.0, 0.0),
            v(0.0, 0.0, size),
            v(size, 0.0, size),
            v(size, 0.0, 0.0),
        ],
        Vec3::Y,
        FLOOR,
        tessellate,
    );
    // Outer walls.
    for (lo, hi) in [
        (v(-t, 0.0, -t), v(size + t, h, t)),
        (v(-t, 0.0, size - t), v(size + t, h, size + t)),
        (v(-t, 0.0, -t), v(t, h, size + t)),
        (v(size - t, 0.0, -t), v(size + t, h, size + t)),
    ] {
        wall(&mut mesh, lo, hi, tessellate);
    }
    let (east, south) = carve();
    for i in 0..n {
        for j in 0..n {
            let (x, z) = (i as f32 * CELL, j as f32 * CELL);
            if i + 1 < n && east[i][j] {
                wall(
                    &mut mesh,
                    v(x + CELL - t, 0.0, z - t),
                    v(x + CELL + t, h, z + CELL + t),
                    tessellate,
                );
            }
            if j + 1 < n && south[i][j] {
                wall(
                    &mut mesh,
                    v(x - t, 0.0, z + CELL - t),
                    v(x + CELL + t, h, z + CELL + t),
                    tessellate,
                );
            }
        }
    }
    (mesh, materials())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maze_is_deterministic_and_connected() {
        let (a, _) = maze(None);
        let (b, _) = maze(None);
        assert_eq!(a.positions, b.positions);
        // A perfect maze on n² cells has n² − 1 openings; the hall removes up to 4 more walls.
        let (east, south) = carve();
        let closed: usize = (0..CELLS)
            .map(|i| {
                (0..CELLS).filter(|&j| i + 1 < CELLS && east[i][j]).count()
                    + (0..CELLS).filter(|&j| j + 1 < CELLS && south[i][j]).count()
            })
            .sum();
        let inner = 2 * CELLS * (CELLS - 1);
        assert!(
            inner - closed >= CELLS * CELLS - 1,
            "{} openings",
            inner - closed
        );
        // Every wall vertex is inside the maze's footprint and height.
        let (lo, hi) = a.bounds();
        assert!(lo.y >= 0.0 && hi.y <= WALL_HEIGHT + 1e-6);
        assert!(hi.x <= CELLS as f32 * CELL + WALL_THICKNESS);
        let t = maze(Some(0.5)).0;
        assert!(t.triangle_count() > 10 * a.triangle_count());
        // Winding agrees with the stored normals.
        for m in [&a, &t] {
            for k in 0..m.triangle_count() {
                let [p0, p1, p2] = m.triangle(k);
                let n = m.normals[m.indices[3 * k] as usize];
                assert!((p1 - p0).cross(p2 - p0).dot(n) > 0.0, "triangle {k}");
            }
        }
    }
}
