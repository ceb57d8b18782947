//! Property tests: the golden ray/triangle test against exact rational arithmetic on the
//! same quantised inputs (integer vertices, integer origin, m-bit direction).

use fxrt::model::golden::Golden;
use fxrt::params::{EdgeShift, Params};
use fxrt::scene::Scene;
use fxrt::scene::accel::{GridVertex, cross, quantize};
use proptest::prelude::*;

const N: u32 = 20;
static HITS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// Exact t (grid units) and barycentrics (weights of x1, x2) as f64 quotients of integers.
fn exact(v: &[GridVertex; 3], o: [i64; 3], w: [i64; 3], f: u32) -> Option<(f64, f64, f64)> {
    let n = cross(v);
    let nw: i128 = (0..3).map(|k| n[k] * w[k] as i128).sum();
    if nw == 0 {
        return None;
    }
    let num: i128 = (0..3).map(|k| n[k] * (v[0][k] - o[k]) as i128).sum::<i128>() << f;
    let t = num as f64 / nw as f64;
    // Hit point relative to x0, then barycentrics from the 2-D system in the (p, q) plane.
    let h: Vec<f64> = (0..3).map(|k| (o[k] - v[0][k]) as f64 + t * w[k] as f64 / (1u64 << f) as f64).collect();
    let (r, p, q) = fxrt::scene::accel::axes(&n);
    let b = [(v[1][p] - v[0][p]) as f64, (v[1][q] - v[0][q]) as f64];
    let c = [(v[2][p] - v[0][p]) as f64, (v[2][q] - v[0][q]) as f64];
    let nr = n[r] as f64;
    let beta = (h[p] * c[1] - h[q] * c[0]) / nr;
    let gamma = (b[0] * h[q] - b[1] * h[p]) / nr;
    Some((t, beta, gamma))
}

fn golden_for(e: u32) -> Golden {
    // A scene only supplies widths and the box; the triangles under test are quantised here.
    let tri = vec![[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 1.0]]];
    let scene = Scene::build("box", tri, &Params { n: N, m: 32, edge_shift: EdgeShift::Fixed(e), ..Params::default() })
        .unwrap();
    Golden::new(&scene)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]
    #[test]
    fn golden_matches_exact_arithmetic(
        verts in prop::array::uniform3(prop::array::uniform3(1000i64..(1 << N) - 1000)),
        origin in prop::array::uniform3(0i64..(1 << N)),
        bary in (-0.2f64..1.0, -0.2f64..1.0),
    ) {
        let f = 31;
        let Some(edge_max) = fxrt::scene::accel::max_edge_ratio(&verts) else { return Ok(()) };
        // The scene-adaptive edge shift for this one triangle, so nothing is clamped.
        let mut e = 0;
        while e < 40 && (edge_max.0 << (e + 1)) <= edge_max.1 { e += 1; }
        let g = golden_for(e);
        let Some(tri) = quantize(&verts, f, e) else { return Ok(()) };
        prop_assume!(!tri.clamped);
        // Aim at a point of the triangle's plane, inside or outside the triangle.
        let (b1, b2) = bary;
        let target: Vec<f64> = (0..3).map(|k| verts[0][k] as f64 + b1 * (verts[1][k] - verts[0][k]) as f64 + b2 * (verts[2][k] - verts[0][k]) as f64).collect();
        let d: Vec<f64> = (0..3).map(|k| target[k] - origin[k] as f64).collect();
        let len = d.iter().map(|x| x * x).sum::<f64>().sqrt();
        prop_assume!(len > 16.0);
        let w = fxrt::model::ray::quantize_direction([d[0] / len, d[1] / len, d[2] / len], f);
        let ray = g.ray(origin, w);
        let Some((t, beta, gamma)) = exact(&verts, origin, w, f) else { return Ok(()) };
        let hit = g.intersect(&tri.tri, &ray);
        // Grazing rays make t ill-conditioned; measure how much, and scale the tolerance.
        let n = cross(&verts);
        let nlen = (n.iter().map(|&x| (x as f64).powi(2)).sum::<f64>()).sqrt();
        let cosine = (0..3).map(|k| n[k] as f64 * w[k] as f64).sum::<f64>().abs() / nlen / (1u64 << f) as f64;
        prop_assume!(cosine > 1e-3);
        // d is rounded to the grid (±0.5 in the numerator → ±0.5/cos in t), t is floored.
        let tol_t = 1.0 + 1.0 / cosine + 4.0 * t * 2f64.powi(-28) / cosine;
        let margin = 1e-5;
        let margin = margin + 2.0 * (edge_max.0 as f64 / edge_max.1 as f64) * (tol_t + 1.0);
        let inside = beta > margin && gamma > margin && beta + gamma < 1.0 - margin && t > tol_t + 1.0 && t < (1u64 << (N + 1)) as f64 - tol_t;
        let outside = beta < -margin || gamma < -margin || beta + gamma > 1.0 + margin;
        HITS.fetch_add(hit.is_some() as usize, std::sync::atomic::Ordering::Relaxed);
        match hit {
            Some(h) => {
                prop_assert!(!outside, "golden hit outside: beta {beta} gamma {gamma}");
                prop_assert!((h.t as f64 - t).abs() <= tol_t, "t {} vs exact {t} (tol {tol_t})", h.t);
                // u weighs x2 and v weighs x1, with F fraction bits. An error δt in t moves the
                // hit point by up to δt per axis, and u = e1p·kq − e1q·kp turns that into
                // at most 2·max|e|·δt.
                let one = (1u64 << f) as f64;
                let tol_uv = 2.0 * (edge_max.0 as f64 / edge_max.1 as f64) * (tol_t + 1.0) + 1e-6;
                prop_assert!((h.u as f64 / one - gamma).abs() <= tol_uv, "u {} vs {gamma}", h.u as f64 / one);
                prop_assert!((h.v as f64 / one - beta).abs() <= tol_uv, "v {} vs {beta}", h.v as f64 / one);
            }
            None => prop_assert!(!inside, "golden missed: t {t} beta {beta} gamma {gamma} cos {cosine}"),
        }
    }
}

#[test]
fn both_outcomes_are_exercised() {
    // Runs the property above again on its own and checks it saw hits (misses are the rest).
    golden_matches_exact_arithmetic();
    let hits = HITS.load(std::sync::atomic::Ordering::Relaxed);
    assert!(hits > 500 && hits < 8000, "{hits} hits in 8000 cases: the property is not testing both outcomes");
}
