//! Random scenes for the differential campaign, made to provoke the cases where a fixed-point
//! traversal and a pipelined one part ways: exact ties. Walls, floors and boxes on a coarse
//! lattice share planes and edges exactly, so ray distances to clip planes equal a node's
//! entry distance, hits tie on t, and leaves hold coplanar triangles; near-coplanar layers
//! differ by a hair; fans and strips share vertices. Every scene is a deterministic function
//! of its seed (SplitMix64 and plain f64 arithmetic), so a reproducer only needs the seed —
//! the campaign still writes the triangles out as OBJ, so a reproducer runs without fxrt's
//! generator too.

use crate::rng::SplitMix64;
use crate::scene::Tri;

/// The kinds of random scene, in the order the campaign cycles through them.
pub const KINDS: [&str; 4] = ["rooms", "layers", "strips", "soup"];

/// The triangles of random scene `kind` (one of `KINDS`) for `seed`, placed at a random
/// offset and scale (so the grid mapping sees awkward world numbers too).
pub fn scene(kind: &str, seed: u64) -> Vec<Tri> {
    let mut rng = SplitMix64(seed);
    let tris = match kind {
        "rooms" => rooms(&mut rng),
        "layers" => layers(&mut rng),
        "strips" => strips(&mut rng),
        _ => soup(&mut rng),
    };
    // 10^-3 … 10^4, and an offset of up to 10^3 scene sizes.
    let scale = 10f64.powf(rng.range(-3.0, 4.0));
    let offset: [f64; 3] = std::array::from_fn(|_| (rng.range(-1.0, 1.0) * 1000.0).round() * scale);
    tris.into_iter().map(|t| t.map(|v| std::array::from_fn(|k| v[k] * scale + offset[k]))).collect()
}

/// The two triangles of the axis-aligned rectangle at `coord` on `axis`, spanning
/// [a0, a1] × [b0, b1] on the other two axes (in cyclic order), split along a diagonal.
fn rect(axis: usize, coord: f64, a: (f64, f64), b: (f64, f64), flip: bool) -> [Tri; 2] {
    let point = |x: f64, y: f64| {
        let mut p = [0.0; 3];
        p[axis] = coord;
        p[(axis + 1) % 3] = x;
        p[(axis + 2) % 3] = y;
        p
    };
    let (p00, p10, p11, p01) = (point(a.0, b.0), point(a.1, b.0), point(a.1, b.1), point(a.0, b.1));
    if flip { [[p00, p10, p01], [p10, p11, p01]] } else { [[p00, p10, p11], [p00, p11, p01]] }
}

/// An axis-aligned box's 12 triangles (its 6 faces), each face split into `sub`² quads.
fn boxed(lo: [f64; 3], hi: [f64; 3], sub: u32, rng: &mut SplitMix64, out: &mut Vec<Tri>) {
    for axis in 0..3 {
        let (p, q) = ((axis + 1) % 3, (axis + 2) % 3);
        for coord in [lo[axis], hi[axis]] {
            for i in 0..sub {
                for j in 0..sub {
                    let step = |k: usize, x: u32| lo[k] + (hi[k] - lo[k]) * x as f64 / sub as f64;
                    let a = (step(p, i), step(p, i + 1));
                    let b = (step(q, j), step(q, j + 1));
                    out.extend(rect(axis, coord, a, b, rng.below(2) == 0));
                }
            }
        }
    }
}

/// An architectural interior: a room (its walls subdivided) with boxes — furniture, pillars,
/// shelves — on an integer lattice, many touching each other or a wall, some nested, some
/// thin as a sheet. The campaign puts cameras inside it.
fn rooms(rng: &mut SplitMix64) -> Vec<Tri> {
    let size = [8 + rng.below(40), 4 + rng.below(20), 8 + rng.below(40)].map(|x| x as f64);
    let mut out = Vec::new();
    boxed([0.0; 3], size, 1 + rng.below(4) as u32, rng, &mut out);
    let boxes = 2 + rng.below(60);
    for _ in 0..boxes {
        let lo: [f64; 3] = std::array::from_fn(|k| rng.below(size[k] as u64) as f64);
        let hi: [f64; 3] = std::array::from_fn(|k| {
            let thin = rng.below(8) == 0;
            let ext = if thin { 0.0 } else { 1.0 + rng.below(6) as f64 };
            (lo[k] + ext).min(size[k])
        });
        // A sheet (zero extent on an axis) is two coplanar rectangles' worth of faces.
        boxed(lo, hi, 1 + rng.below(2) as u32, rng, &mut out);
    }
    out.retain(|t| area2(t) > 0.0);
    out
}

/// Triangulated grids in a few parallel planes, some exactly coplanar, some a hair apart
/// (1e-7 … 1e-3 of the scene), with jittered interior vertices that stay shared between
/// neighbouring triangles.
fn layers(rng: &mut SplitMix64) -> Vec<Tri> {
    let mut out = Vec::new();
    let axis = rng.below(3) as usize;
    let planes = 1 + rng.below(5);
    for _ in 0..planes {
        let base = rng.below(4) as f64;
        let hair = if rng.below(2) == 0 { 0.0 } else { 10f64.powf(rng.range(-7.0, -3.0)) };
        let cells = 2 + rng.below(14) as usize;
        let jitter = rng.range(0.0, 0.45);
        let mut grid = vec![[0.0f64; 2]; (cells + 1) * (cells + 1)];
        for i in 0..=cells {
            for j in 0..=cells {
                let inner = i > 0 && j > 0 && i < cells && j < cells;
                let (dx, dy) =
                    if inner { (rng.range(-jitter, jitter), rng.range(-jitter, jitter)) } else { (0.0, 0.0) };
                grid[i * (cells + 1) + j] = [i as f64 + dx, j as f64 + dy];
            }
        }
        let at = |i: usize, j: usize| {
            let g = grid[i * (cells + 1) + j];
            let mut p = [0.0; 3];
            p[axis] = base + hair;
            p[(axis + 1) % 3] = g[0];
            p[(axis + 2) % 3] = g[1];
            p
        };
        for i in 0..cells {
            for j in 0..cells {
                out.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                out.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
    }
    // Something off the planes, so the scene box has depth on every axis.
    out.push([[0.0, 0.0, 0.0], [1.0, 3.0, 0.5], [0.5, 0.5, 4.0]]);
    out
}

/// Triangle fans and strips around shared vertices, at random orientations: many triangles
/// meet at one point or along one edge, so rays through a vertex tie between them.
fn strips(rng: &mut SplitMix64) -> Vec<Tri> {
    let mut out = Vec::new();
    for _ in 0..1 + rng.below(12) {
        let centre: [f64; 3] = std::array::from_fn(|_| rng.below(8) as f64);
        let spokes = 3 + rng.below(24) as usize;
        let r = 0.5 + rng.below(4) as f64;
        let axis = rng.below(3) as usize;
        let tilt = if rng.below(2) == 0 { 0.0 } else { rng.range(-1.0, 1.0) };
        let rim = |s: usize| {
            let a = std::f64::consts::TAU * s as f64 / spokes as f64;
            let mut p = centre;
            p[(axis + 1) % 3] += r * a.cos();
            p[(axis + 2) % 3] += r * a.sin();
            p[axis] += tilt * a.sin();
            p
        };
        for s in 0..spokes {
            out.push([centre, rim(s), rim(s + 1)]);
        }
    }
    out.retain(|t| area2(t) > 0.0);
    out
}

/// Small random triangles in the unit cube, a tenth of them sliver-thin.
fn soup(rng: &mut SplitMix64) -> Vec<Tri> {
    let count = 1 + rng.below(800);
    (0..count).map(|_| soup_triangle(rng, (-3.0, -0.5))).collect()
}

/// `count` small triangles at random places in the unit cube (sides up to 10^-2, one in ten
/// nearly a line): a large soup for the external-memory figures (`examples/memory_acceptance`),
/// deterministic in `seed`.
pub fn small_soup(seed: u64, count: usize) -> Vec<Tri> {
    let mut rng = SplitMix64(seed);
    (0..count).map(|_| soup_triangle(&mut rng, (-3.0, -2.0))).collect()
}

/// A triangle at a random corner in the unit cube, its other corners within 10^e of it for e
/// drawn from `exponents`; one in ten nearly degenerate (its third corner a hair off the
/// middle of the first two).
fn soup_triangle(rng: &mut SplitMix64, exponents: (f64, f64)) -> Tri {
    let a: [f64; 3] = std::array::from_fn(|_| rng.next_f64());
    let size = 10f64.powf(rng.range(exponents.0, exponents.1));
    let b: [f64; 3] = std::array::from_fn(|k| a[k] + rng.range(-size, size));
    let c: [f64; 3] = if rng.below(10) == 0 {
        std::array::from_fn(|k| a[k] + (b[k] - a[k]) * 0.5 + rng.range(-1e-6, 1e-6))
    } else {
        std::array::from_fn(|k| a[k] + rng.range(-size, size))
    };
    [a, b, c]
}

/// Twice the area's square (nonzero for a proper triangle).
fn area2(t: &Tri) -> f64 {
    let u: [f64; 3] = std::array::from_fn(|k| t[1][k] - t[0][k]);
    let v: [f64; 3] = std::array::from_fn(|k| t[2][k] - t[0][k]);
    let c = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    c.iter().map(|x| x * x).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_is_deterministic_and_builds() {
        for kind in KINDS {
            for seed in 0..20 {
                let a = scene(kind, seed);
                assert!(!a.is_empty(), "{kind} {seed}");
                assert_eq!(a, scene(kind, seed), "{kind} {seed}");
                crate::scene::Scene::build(kind, a, &crate::params::Params::default())
                    .unwrap_or_else(|e| panic!("{kind} {seed}: {e}"));
            }
        }
    }
}
