//! Test vectors for the intersection pipeline: random pairs, rays of a real frame against the
//! triangles their traversal visits, and edge cases. Expected results come from
//! `Golden::intersect`; the generated HDL must reproduce them bit for bit.

use crate::model::camera::Camera;
use crate::model::golden::{Golden, GridRay, TriHit};
use crate::model::ray::{quantize_direction, quantize_ray};
use crate::rng::SplitMix64;
use crate::scene::Scene;
use crate::scene::accel::AccelTri;

/// One pipeline input and the golden answer.
#[derive(Clone, Debug)]
pub struct Vector {
    pub tri: AccelTri,
    pub ray: GridRay,
    pub expected: Option<TriHit>,
}

fn vector(g: &Golden, tri: &AccelTri, ray: GridRay) -> Vector {
    Vector { tri: *tri, ray, expected: g.intersect(tri, &ray) }
}

/// A ray from `o` towards barycentric point (b1, b2) of table triangle `ti`.
fn aimed(scene: &Scene, g: &Golden, ti: usize, o: [i64; 3], b1: f64, b2: f64) -> Option<GridRay> {
    let v = scene.grid_tris[ti];
    let target: [f64; 3] =
        std::array::from_fn(|k| v[0][k] as f64 + b1 * (v[1][k] - v[0][k]) as f64 + b2 * (v[2][k] - v[0][k]) as f64);
    let d: [f64; 3] = std::array::from_fn(|k| target[k] - o[k] as f64);
    let len = d.iter().map(|x| x * x).sum::<f64>().sqrt();
    if len < 1.0 {
        return None;
    }
    let w = quantize_direction(d.map(|x| x / len), g.f);
    (w != [0; 3]).then(|| g.ray(o, w))
}

/// `count` vectors: a third random pairs aimed at or near their triangle, a third from a
/// rendered frame, and the rest edge cases (cycled).
pub fn generate(scene: &Scene, count: usize, seed: u64) -> Vec<Vector> {
    let g = Golden::new(scene);
    let mut rng = SplitMix64(seed);
    let mut out = Vec::with_capacity(count);
    let hi = scene.grid_box.hi;
    let nt = scene.tris.len() as u64;
    // 1. Random origins aimed at random points in and around random triangles.
    while out.len() < count / 3 {
        let ti = rng.below(nt) as usize;
        let o: [i64; 3] = std::array::from_fn(|k| rng.below(hi[k] as u64 + 1) as i64);
        let (b1, b2) = (rng.next_f64() * 1.2 - 0.1, rng.next_f64() * 1.2 - 0.1);
        if let Some(ray) = aimed(scene, &g, ti, o, b1, b2) {
            out.push(vector(&g, &scene.tris[ti], ray));
        }
    }
    // 2. A frame's rays against every triangle their traversal hands to the pipeline.
    let side = ((count / 3) as f64).sqrt().ceil().max(4.0) as u32;
    let cam = Camera::default_for(scene, side, side);
    'frame: for py in 0..side {
        for px in 0..side {
            if let Some(q) = quantize_ray(scene, &g, &cam.ray(px, py)) {
                let mut tris = Vec::new();
                g.traverse(scene, &q.ray, |t, _| tris.push(t));
                for t in tris {
                    if out.len() >= 2 * count / 3 {
                        break 'frame;
                    }
                    out.push(vector(&g, &scene.tris[t as usize], q.ray));
                }
            }
        }
    }
    // 3. Edge cases, cycled until the count is reached.
    let f = g.f;
    let one = (1i64 << f) - 1;
    let top = hi;
    let mut k = 0u64;
    while out.len() < count {
        let ti = rng.below(nt) as usize;
        let tri = scene.tris[ti];
        let v = scene.grid_tris[ti];
        let case = k % 8;
        k += 1;
        let ray = match case {
            // Exactly at a vertex or along an edge: u, v or u + v on the boundary.
            0 => aimed(
                scene,
                &g,
                ti,
                [rng.below(top[0] as u64) as i64, rng.below(top[1] as u64) as i64, rng.below(top[2] as u64) as i64],
                [0.0, 1.0, 0.0][rng.below(3) as usize],
                0.0,
            ),
            1 => aimed(scene, &g, ti, [0, 0, 0], 0.5, 0.5),
            2 => {
                let t = rng.next_f64();
                aimed(scene, &g, ti, top, t, 0.0)
            }
            // Parallel to the plane (zero or tiny denominator): along an edge direction.
            3 => {
                let d: [f64; 3] = std::array::from_fn(|j| (v[1][j] - v[0][j]) as f64);
                let len = d.iter().map(|x| x * x).sum::<f64>().sqrt();
                let o: [i64; 3] = std::array::from_fn(|j| rng.below(top[j] as u64 + 1) as i64);
                Some(g.ray(o, quantize_direction(d.map(|x| x / len), f)))
            }
            // Extreme origins and axis directions: corners of the box, ±(2^F − 1).
            4 => {
                let o: [i64; 3] = std::array::from_fn(|j| if rng.below(2) == 0 { 0 } else { top[j] });
                let mut w = [0i64; 3];
                w[rng.below(3) as usize] = if rng.below(2) == 0 { one } else { -one };
                Some(g.ray(o, w))
            }
            // The smallest direction: t overflows the n + 1 quotient bits.
            5 => {
                let o: [i64; 3] = std::array::from_fn(|j| rng.below(top[j] as u64 + 1) as i64);
                let mut w = [0i64; 3];
                w[tri.r as usize] = if rng.below(2) == 0 { 1 } else { -1 };
                Some(g.ray(o, w))
            }
            // Origin on the triangle's plane (t = 0) or one unit off it (t near 1).
            6 => {
                let o = v[0];
                let w = quantize_direction(
                    [rng.next_f64() - 0.5, rng.next_f64() - 0.5, rng.next_f64() - 0.5].map(|x| x * 2.0),
                    f,
                );
                Some(g.ray(o, w))
            }
            _ => {
                let mut o = v[0];
                o[tri.r as usize] = (o[tri.r as usize] + 1).min(top[tri.r as usize]);
                aimed(scene, &g, ti, o, 0.3, 0.3)
            }
        };
        if let Some(ray) = ray.filter(|r| r.w != [0; 3]) {
            out.push(vector(&g, &tri, ray));
        }
    }
    out.truncate(count);
    out
}
