//! The bit-exact integer reference: exactly what the hardware computes. docs/ARITHMETIC.md
//! states every operation with its width and rounding; this file is its executable form.
//! All values fit i128 because `Params::validate` bounds the widths.

use crate::scene::Scene;
use crate::scene::accel::AccelTri;
use crate::scene::bih::{Node, Step, inner_step};

/// A ray on the grid: origin (n-bit unsigned), direction (m-bit signed, F fraction bits),
/// reciprocal direction (m+C-bit signed, F+C fraction bits).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
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
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Hit {
    pub tri: u32,
    pub t: i64,
    pub u: i64,
    pub v: i64,
}

/// Per-ray traversal figures (what the hardware FSM would count).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalStats {
    /// Nodes visited (inner steps and leaves), not counting culled entries.
    pub nodes: u32,
    /// Node entries skipped by the visitor's `prune` (the early-out walk's culls).
    pub culled: u32,
    pub tri_tests: u32,
    pub max_stack: u32,
    /// Leaves visited (among `nodes`), and of them those entered straight from their parent's
    /// step (not popped, not the root): the node steps a traversal unit would save if a
    /// parent's step sent such a leaf to the leaf stream itself (docs/CORE.md, the ceiling).
    /// `walk` counts them; `render::fast` leaves them 0.
    pub leaves: u32,
    pub leaves_from_parent: u32,
    /// Of those, the leaves entered as the near child (with or without the far one pushed),
    /// with entries: what a spread core's unit sends from its parent's step (DECISIONS 137).
    pub near_leaves: u32,
}

/// The constants of one parameter set, precomputed for speed.
#[derive(Clone, Debug)]
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
    #[inline]
    pub fn reciprocal(&self, w: i64, m_plus_c: u32) -> i128 {
        let w = if w == 0 { 1 } else { w };
        let lim = (1i128 << (m_plus_c - 1)) - 1;
        // Truncating division is the same in i64 when 2^(F+C) fits (and skips __divti3).
        let q = if self.f + self.c <= 62 {
            ((1i64 << (self.f + self.c)) / w) as i128
        } else {
            (1i128 << (self.f + self.c)) / w as i128
        };
        q.clamp(-lim, lim)
    }

    #[inline]
    pub fn ray(&self, o: [i64; 3], w: [i64; 3]) -> GridRay {
        let mc = self.f + 1 + self.c;
        GridRay { o, w, inv: [self.reciprocal(w[0], mc), self.reciprocal(w[1], mc), self.reciprocal(w[2], mc)] }
    }

    /// Ray/triangle (eq. 2.1, 2.2) with the hardware divider's semantics. Every product has
    /// 64-bit operands (`wmul`), so it is exact in i128 and costs one machine multiply.
    #[inline]
    pub fn intersect(&self, tri: &AccelTri, ray: &GridRay) -> Option<TriHit> {
        let (r, p, q) = perm(tri.r);
        let f = self.f;
        // Numerator with F fraction bits (exact), denominator rounded to F fraction bits.
        let num = (((tri.d - ray.o[r]) as i128) << f) - wmul(ray.o[p], tri.np) - wmul(ray.o[q], tri.nq);
        let den = ray.w[r] as i128 + shr_round(wmul(ray.w[p], tri.np) + wmul(ray.w[q], tri.nq), f);
        // Division precision T: both operands lose their T low bits (floor).
        let t = self.divide(num >> self.t, den >> self.t)?;
        let kp = (ray.o[p] - tri.pp) + shr_round(wmul(t, ray.w[p]), f) as i64;
        let kq = (ray.o[q] - tri.pq) + shr_round(wmul(t, ray.w[q]), f) as i64;
        // Barycentrics with E+F fraction bits: u weighs x2, v weighs x1.
        let u = wmul(tri.e1p, kq) - wmul(tri.e1q, kp);
        let v = wmul(tri.e2q, kp) - wmul(tri.e2p, kq);
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
        let (a, b) = (num.unsigned_abs(), den.unsigned_abs());
        if a < b || a >= b << (self.n + 1) {
            return None;
        }
        Some(floor_div(a, b) as i64)
    }

    /// Distance to the axis plane x_axis = plane: ((plane − O) · inv) >> C, saturated.
    #[inline(always)]
    pub fn plane_t(&self, ray: &GridRay, axis: usize, plane: i64) -> i64 {
        let d = plane - ray.o[axis];
        let inv = ray.inv[axis];
        let prod = if inv as i64 as i128 == inv { wmul(d, inv as i64) } else { d as i128 * inv };
        (prod >> self.c).clamp(-1, self.t_sat as i128) as i64
    }

    /// Exit distance of the scene box (the ray origin is inside it).
    pub fn box_exit(&self, ray: &GridRay) -> i64 {
        (0..3).map(|k| self.plane_t(ray, k, if ray.inv[k] < 0 { 0 } else { self.box_hi[k] })).min().unwrap_or(-1)
    }

    /// BIH traversal in the hardware FSM's order: near child first, far child pushed; every
    /// triangle of every visited leaf is handed to the visitor with the leaf's entry distance
    /// (no early out, as in seed 001). A visitor may prune: then a node whose entry distance
    /// it rejects is skipped as if both children were missed (software early out).
    pub fn walk(&self, scene: &Scene, ray: &GridRay, visitor: &mut impl Visitor) -> TraversalStats {
        let mut stats = TraversalStats::default();
        let tmax0 = self.box_exit(ray);
        if tmax0 < 0 {
            return stats;
        }
        // The hardware stack holds at most stack_depth ≤ 256 entries (Params::validate). Left
        // uninitialised: zeroing 6 KiB per ray cost more than the traversal of a small scene.
        let mut stack = [const { std::mem::MaybeUninit::<(u32, i64, i64)>::uninit() }; 256];
        let mut sp = 0usize;
        let (mut node, mut tmin, mut tmax) = (0u32, 0i64, tmax0);
        let nodes = &scene.bih.nodes;
        let (mut from_parent, mut near) = (false, false);
        loop {
            let mut go_pop = visitor.prune(tmin);
            stats.culled += go_pop as u32;
            if !go_pop {
                stats.nodes += 1;
                visitor.node(node);
                match nodes[node as usize] {
                    Node::Inner { axis, clip0, clip1, child } => {
                        let a = axis as usize;
                        let d0 = self.plane_t(ray, a, clip0);
                        let d1 = self.plane_t(ray, a, clip1);
                        match inner_step(child, ray.inv[a] >= 0, d0, d1, tmin, tmax) {
                            Step::Both { near: child, near_max, far, far_min } => {
                                stack[sp].write((far, far_min, tmax));
                                sp += 1;
                                stats.max_stack = stats.max_stack.max(sp as u32);
                                (node, tmax, near) = (child, near_max, true);
                            }
                            Step::Near(child, near_max) => (node, tmax, near) = (child, near_max, true),
                            Step::Far(far, far_min) => (node, tmin, near) = (far, far_min, false),
                            Step::Neither => go_pop = true,
                        }
                    }
                    Node::Leaf { first, count } => {
                        for &t in &scene.bih.leaf_tris[first as usize..(first + count) as usize] {
                            visitor.triangle(t, tmin);
                        }
                        stats.tri_tests += count;
                        stats.leaves += 1;
                        stats.leaves_from_parent += from_parent as u32;
                        stats.near_leaves += (from_parent && near && count > 0) as u32;
                        go_pop = true;
                    }
                }
            }
            if go_pop {
                if sp == 0 {
                    return stats;
                }
                sp -= 1;
                // SAFETY: entries below the stack pointer were written by a push.
                (node, tmin, tmax) = unsafe { stack[sp].assume_init() };
            }
            from_parent = !go_pop;
        }
    }

    /// The full traversal, calling `visit(triangle, leaf entry distance)` in FSM order.
    pub fn traverse(&self, scene: &Scene, ray: &GridRay, visit: impl FnMut(u32, i64)) -> TraversalStats {
        struct All<F>(F);
        impl<F: FnMut(u32, i64)> Visitor for All<F> {
            fn triangle(&mut self, tri: u32, leaf_tmin: i64) {
                (self.0)(tri, leaf_tmin)
            }
        }
        self.walk(scene, ray, &mut All(visit))
    }

    /// Closest hit over every triangle the hardware traversal visits: the smallest
    /// (t, triangle number) among accepted hits, so test order does not matter. A hit is
    /// accepted only if t ≥ lower_t(entry distance of its leaf) — see `lower_t`.
    /// (`render::fast` computes the same answer faster.)
    pub fn trace(&self, scene: &Scene, ray: &GridRay) -> (Option<Hit>, TraversalStats) {
        let mut c = Closest::new(self, scene, ray);
        let stats = self.walk(scene, ray, &mut c);
        (c.best, stats)
    }

    /// The early-out walk the hardware makes (docs/ARITHMETIC.md §6): `walk` in the same order,
    /// with every node entry (descent or pop) skipped when lower_t(its tmin) > the best t of
    /// every triangle tested before it. The same answer as `trace`; its node, cull and
    /// triangle counts are the hardware's.
    pub fn trace_culled(&self, scene: &Scene, ray: &GridRay) -> (Option<Hit>, TraversalStats) {
        let mut c = Culled(Closest::new(self, scene, ray));
        let stats = self.walk(scene, ray, &mut c);
        (c.0.best, stats)
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

/// Smallest t accepted for a triangle of a leaf entered at distance `leaf_tmin`:
/// leaf_tmin − leaf_tmin/64 − 8. A true hit lies inside its leaf's box, so this only rejects
/// hits whose t is off by more than 1/64 + 8 units; it is what makes an early out exact: a
/// node entered beyond lower_t⁻¹(best t) cannot hold a better hit (lower_t is monotone).
#[inline(always)]
pub fn lower_t(leaf_tmin: i64) -> i64 {
    leaf_tmin - (leaf_tmin >> 6) - 8
}

/// What a traversal does with the triangles of each visited leaf.
pub trait Visitor {
    fn triangle(&mut self, tri: u32, leaf_tmin: i64);
    /// True to skip a node entered at `tmin`. The hardware never skips.
    fn prune(&self, _tmin: i64) -> bool {
        false
    }
    /// Called on every node visit, before its children or triangles.
    fn node(&mut self, _node: u32) {}
}

/// The visitor of `trace`: the smallest (t, triangle number) among accepted hits.
pub struct Closest<'a> {
    g: &'a Golden,
    scene: &'a Scene,
    ray: &'a GridRay,
    pub best: Option<Hit>,
}

impl<'a> Closest<'a> {
    pub fn new(g: &'a Golden, scene: &'a Scene, ray: &'a GridRay) -> Self {
        Closest { g, scene, ray, best: None }
    }
}

impl Visitor for Closest<'_> {
    #[inline]
    fn triangle(&mut self, i: u32, leaf_tmin: i64) {
        if let Some(h) = self.g.intersect(&self.scene.tris[i as usize], self.ray)
            && h.t >= lower_t(leaf_tmin)
            && self.best.is_none_or(|b| (h.t, i) < (b.t, b.tri))
        {
            self.best = Some(Hit { tri: i, t: h.t, u: h.u, v: h.v });
        }
    }
}

/// The visitor of `trace_culled`: `Closest`, skipping every node entered beyond
/// lower_t⁻¹(best t) — no accepted hit below it can be nearer or equal (lower_t is monotone,
/// tmin only grows down the tree).
pub struct Culled<'a>(pub Closest<'a>);

impl Visitor for Culled<'_> {
    #[inline]
    fn triangle(&mut self, tri: u32, leaf_tmin: i64) {
        self.0.triangle(tri, leaf_tmin)
    }
    #[inline]
    fn prune(&self, tmin: i64) -> bool {
        self.0.best.is_some_and(|b| lower_t(tmin) > b.t)
    }
    fn node(&mut self, node: u32) {
        self.0.node(node)
    }
}

/// Exact product of two 64-bit values (a single widening multiply).
#[inline(always)]
pub fn wmul(a: i64, b: i64) -> i128 {
    a as i128 * b as i128
}

/// floor(a / b) for a quotient known to be below 2^53: a float estimate corrected to the
/// exact integer (a 128-bit division would dominate the model's run time).
#[inline(always)]
fn floor_div(a: u128, b: u128) -> u128 {
    // u64 → f64 is one instruction; u128 → f64 is a library call.
    let to_f64 = |x: u128| if x >> 64 == 0 { x as u64 as f64 } else { x as f64 };
    let mut q = (to_f64(a) / to_f64(b)) as u64 as u128;
    while q * b > a {
        q -= 1;
    }
    while (q + 1) * b <= a {
        q += 1;
    }
    q
}

/// (r, p, q) from the stored projection axis.
#[inline(always)]
pub fn perm(r: u8) -> (usize, usize, usize) {
    let r = r as usize;
    (r, (r + 1) % 3, (r + 2) % 3)
}
