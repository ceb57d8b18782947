//! The bit-exact integer reference: exactly what the hardware computes. docs/ARITHMETIC.md
//! states every operation with its width and rounding; this file is its executable form.
//! All values fit i128 because `Params::validate` bounds the widths.

use crate::scene::Scene;
use crate::scene::accel::AccelTri;
use crate::scene::bih::Node;

/// A ray on the grid: origin (n-bit unsigned), direction (m-bit signed, F fraction bits),
/// reciprocal direction (m+C-bit signed, F+C fraction bits).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GridRay {
    pub o: [i64; 3],
    pub w: [i64; 3],
    pub inv: [i128; 3],
}

/// Result of one ray/triangle test: t in grid units, u and v with F fraction bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TriHit {
    pub t: i64,
    pub u: i64,
    pub v: i64,
}

/// The closest hit of a ray: `tri` indexes the scene's triangle table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Hit {
    pub tri: u32,
    pub t: i64,
    pub u: i64,
    pub v: i64,
}

/// Per-ray traversal figures (what the hardware FSM would count).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalStats {
    pub nodes: u32,
    pub tri_tests: u32,
    pub max_stack: u32,
}

/// The constants of one parameter set, precomputed for speed.
#[derive(Clone, Copy, Debug)]
pub struct Golden {
    pub n: u32,
    pub f: u32,
    pub t: u32,
    pub c: u32,
    pub e: u32,
    pub box_hi: [i64; 3],
    /// Plane distances saturate to [−1, 2^(n+1)]: every comparison the traversal makes
    /// involves a value in [0, 2^(n+1)), so saturation changes no decision.
    pub t_sat: i64,
}

/// Arithmetic shift right with rounding half up: floor((x + 2^(s−1)) / 2^s).
#[inline(always)]
pub fn shr_round(x: i128, s: u32) -> i128 {
    if s == 0 { x } else { (x + (1i128 << (s - 1))) >> s }
}

impl Golden {
    pub fn new(scene: &Scene) -> Golden {
        let p = &scene.params;
        Golden {
            n: p.n,
            f: p.f(),
            t: p.t,
            c: p.c,
            e: scene.edge_shift,
            box_hi: scene.grid_box.hi,
            t_sat: 1i64 << (p.n + 1),
        }
    }

    /// Reciprocal direction in m+C bits: trunc(2^(F+C) / ω), with ω = 0 treated as +1 (the
    /// smallest positive direction), saturated to the m+C-bit signed range.
    pub fn reciprocal(&self, w: i64, m_plus_c: u32) -> i128 {
        let w = if w == 0 { 1 } else { w as i128 };
        let lim = (1i128 << (m_plus_c - 1)) - 1;
        ((1i128 << (self.f + self.c)) / w).clamp(-lim, lim)
    }

    pub fn ray(&self, o: [i64; 3], w: [i64; 3]) -> GridRay {
        let mc = self.f + 1 + self.c;
        GridRay { o, w, inv: w.map(|x| self.reciprocal(x, mc)) }
    }

    /// Ray/triangle (eq. 2.1, 2.2) with the hardware divider's semantics.
    #[inline]
    pub fn intersect(&self, tri: &AccelTri, ray: &GridRay) -> Option<TriHit> {
        let (r, p, q) = perm(tri.r);
        let f = self.f;
        let (np, nq) = (tri.np as i128, tri.nq as i128);
        let (op, oq) = (ray.o[p] as i128, ray.o[q] as i128);
        let (wp, wq) = (ray.w[p] as i128, ray.w[q] as i128);
        // Numerator with F fraction bits (exact), denominator rounded to F fraction bits.
        let num = (((tri.d - ray.o[r]) as i128) << f) - op * np - oq * nq;
        let den = ray.w[r] as i128 + shr_round(wp * np + wq * nq, f);
        // Division precision T: both operands lose their T low bits (floor).
        let (num, den) = (num >> self.t, den >> self.t);
        let t = self.divide(num, den)?;
        let kp = (ray.o[p] - tri.pp) as i128 + shr_round(t as i128 * wp, f);
        let kq = (ray.o[q] - tri.pq) as i128 + shr_round(t as i128 * wq, f);
        // Barycentrics with E+F fraction bits: u weighs x2, v weighs x1.
        let u = tri.e1p as i128 * kq - tri.e1q as i128 * kp;
        let v = tri.e2q as i128 * kp - tri.e2p as i128 * kq;
        if u < 0 || v < 0 || u + v > 1i128 << (self.e + f) {
            return None;
        }
        Some(TriHit { t, u: (u >> self.e) as i64, v: (v >> self.e) as i64 })
    }

    /// The specialised divider: t = floor(|num| / |den|), only when the signs agree and
    /// 1 ≤ t < 2^(n+1) (a hit inside the box); otherwise the error bit (None).
    #[inline(always)]
    pub fn divide(&self, num: i128, den: i128) -> Option<i64> {
        if den == 0 || num == 0 || (num < 0) != (den < 0) {
            return None;
        }
        let (a, b) = (num.abs(), den.abs());
        if a < b || a >= b << (self.n + 1) {
            return None;
        }
        Some((a / b) as i64)
    }

    /// Distance to the axis plane x_axis = plane: ((plane − O) · inv) >> C, saturated.
    #[inline(always)]
    pub fn plane_t(&self, ray: &GridRay, axis: usize, plane: i64) -> i64 {
        let prod = (plane - ray.o[axis]) as i128 * ray.inv[axis];
        (prod >> self.c).clamp(-1, self.t_sat as i128) as i64
    }

    /// Exit distance of the scene box (the ray origin is inside it).
    pub fn box_exit(&self, ray: &GridRay) -> i64 {
        (0..3)
            .map(|k| self.plane_t(ray, k, if ray.inv[k] < 0 { 0 } else { self.box_hi[k] }))
            .min()
            .unwrap_or(-1)
    }

    /// BIH traversal in the hardware FSM's order: near child first, far child pushed; every
    /// triangle of every visited leaf is handed to `visit` (no early out, as in seed 001).
    pub fn traverse(&self, scene: &Scene, ray: &GridRay, mut visit: impl FnMut(u32)) -> TraversalStats {
        let mut stats = TraversalStats::default();
        let tmax0 = self.box_exit(ray);
        if tmax0 < 0 {
            return stats;
        }
        let mut stack: [(u32, i64, i64); 256] = [(0, 0, 0); 256];
        let mut sp = 0usize;
        let (mut node, mut tmin, mut tmax) = (0u32, 0i64, tmax0);
        let nodes = &scene.bih.nodes;
        loop {
            stats.nodes += 1;
            let mut go_pop = false;
            match nodes[node as usize] {
                Node::Inner { axis, clip0, clip1, child } => {
                    let a = axis as usize;
                    let d0 = self.plane_t(ray, a, clip0);
                    let d1 = self.plane_t(ray, a, clip1);
                    // Positive direction: left (below clip0) is near. Negative: right.
                    let (near, far, near_end, far_start) =
                        if ray.inv[a] >= 0 { (child, child + 1, d0, d1) } else { (child + 1, child, d1, d0) };
                    let near_max = tmax.min(near_end);
                    let far_min = tmin.max(far_start);
                    let near_ok = tmin <= near_max;
                    let far_ok = far_min <= tmax;
                    match (near_ok, far_ok) {
                        (true, true) => {
                            stack[sp] = (far, far_min, tmax);
                            sp += 1;
                            stats.max_stack = stats.max_stack.max(sp as u32);
                            node = near;
                            tmax = near_max;
                        }
                        (true, false) => {
                            node = near;
                            tmax = near_max;
                        }
                        (false, true) => {
                            node = far;
                            tmin = far_min;
                        }
                        (false, false) => go_pop = true,
                    }
                }
                Node::Leaf { first, count } => {
                    for &t in &scene.bih.leaf_tris[first as usize..(first + count) as usize] {
                        visit(t);
                    }
                    stats.tri_tests += count;
                    go_pop = true;
                }
            }
            if go_pop {
                if sp == 0 {
                    return stats;
                }
                sp -= 1;
                (node, tmin, tmax) = stack[sp];
            }
        }
    }

    /// Closest hit: the smallest (t, triangle number), so test order does not matter.
    pub fn trace(&self, scene: &Scene, ray: &GridRay) -> (Option<Hit>, TraversalStats) {
        let mut best: Option<Hit> = None;
        let stats = self.traverse(scene, ray, |i| {
            if let Some(h) = self.intersect(&scene.tris[i as usize], ray) {
                if best.is_none_or(|b| (h.t, i) < (b.t, b.tri)) {
                    best = Some(Hit { tri: i, t: h.t, u: h.u, v: h.v });
                }
            }
        });
        (best, stats)
    }

    /// The hit point rounded to the grid: h_k = O_k + round(t·ω_k / 2^F) (seed 001 §2.1.5).
    pub fn hit_point(&self, ray: &GridRay, t: i64) -> [i64; 3] {
        std::array::from_fn(|k| ray.o[k] + shr_round(t as i128 * ray.w[k] as i128, self.f) as i64)
    }

    /// Origin of a secondary ray leaving `tri` at `hit` with direction `w`: the hit point
    /// moved 2 grid units per axis to the side of the surface the new ray travels into.
    pub fn spawn_origin(&self, tri: &AccelTri, hit: [i64; 3], w: [i64; 3]) -> [i64; 3] {
        let (r, p, q) = perm(tri.r);
        let mut normal = [0i64; 3];
        normal[r] = 1;
        normal[p] = tri.np;
        normal[q] = tri.nq;
        let dt = w[r] as i128 + shr_round(w[p] as i128 * tri.np as i128 + w[q] as i128 * tri.nq as i128, self.f);
        std::array::from_fn(|k| {
            let step = if (dt > 0) ^ (normal[k] < 0) { 2 } else { -2 };
            (hit[k] + step).clamp(0, self.box_hi[k])
        })
    }
}

/// (r, p, q) from the stored projection axis.
#[inline(always)]
pub fn perm(r: u8) -> (usize, usize, usize) {
    let r = r as usize;
    (r, (r + 1) % 3, (r + 2) % 3)
}
