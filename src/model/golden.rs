//! The bit-exact integer reference: exactly what the hardware computes. docs/ARITHMETIC.md
//! states every operation with its width and rounding; this file is its executable form.
//! All values fit i128 because `Params::validate` bounds the widths.

use crate::model::ray::NarrowRay;
use crate::params::Params;
use crate::scene::Scene;
use crate::scene::accel::AccelTri;
use crate::scene::bih::{Node, Step, inner_step};
use std::mem::MaybeUninit;
use std::sync::Arc;

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

/// The constants of one parameter set, precomputed for speed. A Golden belongs to the scene
/// it was made from.
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
    /// The scene laid out for `trace_fast`'s i64 path, when its widths and values allow it.
    fast: Option<Arc<FastScene>>,
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
            fast: FastScene::new(scene).map(Arc::new),
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
        loop {
            let mut go_pop = visitor.prune(tmin);
            if !go_pop {
                stats.nodes += 1;
                visitor.node(node);
                match nodes[node as usize] {
                    Node::Inner { axis, clip0, clip1, child } => {
                        let a = axis as usize;
                        let d0 = self.plane_t(ray, a, clip0);
                        let d1 = self.plane_t(ray, a, clip1);
                        match inner_step(child, ray.inv[a] >= 0, d0, d1, tmin, tmax) {
                            Step::Both { near, near_max, far, far_min } => {
                                stack[sp].write((far, far_min, tmax));
                                sp += 1;
                                stats.max_stack = stats.max_stack.max(sp as u32);
                                (node, tmax) = (near, near_max);
                            }
                            Step::Near(near, near_max) => (node, tmax) = (near, near_max),
                            Step::Far(far, far_min) => (node, tmin) = (far, far_min),
                            Step::Neither => go_pop = true,
                        }
                    }
                    Node::Leaf { first, count } => {
                        for &t in &scene.bih.leaf_tris[first as usize..(first + count) as usize] {
                            visitor.triangle(t, tmin);
                        }
                        stats.tri_tests += count;
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
    pub fn trace(&self, scene: &Scene, ray: &GridRay) -> (Option<Hit>, TraversalStats) {
        let mut c = Closest { g: self, scene, ray, best: None, early_out: false };
        let stats = self.walk(scene, ray, &mut c);
        (c.best, stats)
    }

    /// The same answer as `trace`, bit for bit, but skipping every node whose entry distance
    /// proves it cannot hold a better hit (what makes the software model fast).
    pub fn trace_fast(&self, scene: &Scene, ray: &GridRay) -> (Option<Hit>, TraversalStats) {
        if let (Some(fs), Some(nr)) = (self.fast_scene(scene), NarrowRay::new(self, ray)) {
            return self.trace_narrow(fs, &nr);
        }
        let mut c = Closest { g: self, scene, ray, best: None, early_out: true };
        let stats = self.walk(scene, ray, &mut c);
        (c.best, stats)
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

struct Closest<'a> {
    g: &'a Golden,
    scene: &'a Scene,
    ray: &'a GridRay,
    best: Option<Hit>,
    early_out: bool,
}

impl Visitor for Closest<'_> {
    #[inline]
    fn triangle(&mut self, i: u32, leaf_tmin: i64) {
        if let Some(h) = self.g.intersect(&self.scene.tris[i as usize], self.ray) {
            if h.t >= lower_t(leaf_tmin) && self.best.is_none_or(|b| (h.t, i) < (b.t, b.tri)) {
                self.best = Some(Hit { tri: i, t: h.t, u: h.u, v: h.v });
            }
        }
    }
    #[inline]
    fn prune(&self, tmin: i64) -> bool {
        self.early_out && self.best.is_some_and(|b| lower_t(tmin) > b.t)
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

// The i64 path of `trace_fast`. It computes every value `trace` computes, with the same
// formulas, in i64 instead of i128 where the widths bound them (`narrow_widths`), and walks
// a copy of the BIH laid out for speed. With B = 2^n, S = 2^F and, checked per scene and per
// ray, 0 ≤ O, pp, pq, clip, box_hi < B, |d| < 3B, |np|, |nq|, |e..|, |ω| < S, |inv| < 2^(F+C):
// - num: |(d − O_r)·S| < 4BS, |O_p·np| + |O_q·nq| < 2BS, so |num| < 2^(n+F+3) ≤ 2^63 (n+m ≤ 61);
// - den: |ω_p·np + ω_q·nq| + S/2 < 2S² ≤ 2^63 (m ≤ 32), so |den| < 3S and (hi+1)·|den| < 6BS;
// - t < 2B, so |t·ω| < 2BS, |kp|, |kq| < 3B and |u|, |v| < 6BS < 2^63;
// - traversal: |(P − O)·inv_hi| < B·2^F and |(P − O)·inv_lo| < 2^(n+C) ≤ 2^62 (see NarrowAxis).

fn narrow_widths(p: &Params) -> bool {
    p.n + p.m <= 61 && p.m <= 32 && p.m + p.c <= 64 && p.n + p.c <= 62
}

/// The BIH with each leaf's triangles copied next to each other in leaf order.
pub(crate) struct FastScene {
    pub(crate) nodes: Vec<FastNode>,
    pub(crate) tris: Vec<FastTri>,
    /// Address and length of the triangle table it was made from.
    source: (usize, usize),
}

pub(crate) const LEAF: u32 = 3;

pub(crate) struct FastNode {
    pub(crate) clips: [i64; 2],
    /// Inner node: children link and link + 1. Leaf: tris[link..link + kind − LEAF].
    pub(crate) link: u32,
    /// The split axis of an inner node (< LEAF), or LEAF + the leaf's triangle count.
    pub(crate) kind: u32,
}

pub(crate) struct FastTri {
    pub(crate) tri: AccelTri,
    /// Its number in the scene's triangle table.
    pub(crate) id: u32,
}

impl std::fmt::Debug for FastScene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "FastScene({} nodes, {} triangles)", self.nodes.len(), self.tris.len())
    }
}

impl FastScene {
    /// None when the widths or any value of the scene are outside the bounds above.
    fn new(scene: &Scene) -> Option<FastScene> {
        let p = &scene.params;
        let (b, s) = (1i64 << p.n, 1i64 << p.f());
        if !narrow_widths(p) || !scene.grid_box.hi.iter().all(|h| (0..b).contains(h)) {
            return None;
        }
        let fits = |t: &AccelTri| {
            let small = [t.np, t.nq, t.e1p, t.e1q, t.e2p, t.e2q].iter().all(|x| x.abs() < s);
            t.r < 3 && (0..b).contains(&t.pp) && (0..b).contains(&t.pq) && t.d.abs() < 3 * b && small
        };
        let (bih, count) = (&scene.bih, scene.bih.nodes.len());
        let mut tris = Vec::with_capacity(bih.leaf_tris.len());
        let mut nodes = Vec::with_capacity(count);
        for node in &bih.nodes {
            nodes.push(match *node {
                Node::Inner { axis, clip0, clip1, child } => {
                    let ok =
                        axis < 3 && (child as usize) + 1 < count && [clip0, clip1].iter().all(|c| (0..b).contains(c));
                    ok.then_some(FastNode { clips: [clip0, clip1], link: child, kind: axis as u32 })?
                }
                Node::Leaf { first, count } => {
                    let link = tris.len() as u32;
                    for &id in &bih.leaf_tris[first as usize..(first + count) as usize] {
                        let tri = scene.tris[id as usize];
                        fits(&tri).then(|| tris.push(FastTri { tri, id }))?;
                    }
                    FastNode { clips: [0; 2], link, kind: LEAF + count }
                }
            });
        }
        Some(FastScene { nodes, tris, source: (scene.tris.as_ptr() as usize, scene.tris.len()) })
    }
}

impl Golden {
    /// The scene's fast layout, when it has one and `scene` is the scene it was made from.
    #[inline]
    pub(crate) fn fast_scene(&self, scene: &Scene) -> Option<&FastScene> {
        self.fast.as_deref().filter(|fs| fs.source == (scene.tris.as_ptr() as usize, scene.tris.len()))
    }

    /// `intersect` in i64, also rejecting every t outside [lo, hi] (1 ≤ lo, hi < 2^(n+1))
    /// before dividing, by comparing products; inside the window it returns what `intersect`
    /// does. `uv_max` is 2^(E+F) as a u64 (saturated: u + v < 2^64 never exceeds it then).
    #[inline(always)]
    fn intersect_narrow(&self, tri: &AccelTri, ray: &NarrowRay, lo: i64, hi: i64, uv_max: u64) -> Option<TriHit> {
        // r < 3 was checked by FastScene::new; `& 3` spares the bounds check.
        let [or, op, oq, wr, wp, wq] = ray.rows[tri.r as usize & 3];
        let (f, half) = (self.f, 1i64 << (self.f - 1));
        let den = (wr + ((wp * tri.np + wq * tri.nq + half) >> f)) >> self.t;
        let num = (((tri.d - or) << f) - op * tri.np - oq * tri.nq) >> self.t;
        // The divider's sign rule. A zero den or num fails the range test below (lo ≥ 1).
        if (num ^ den) < 0 {
            return None;
        }
        let (a, b) = (num.abs(), den.abs());
        if a < lo * b || a >= (hi + 1) * b {
            return None;
        }
        let t = div_floor(a, b);
        let kp = (op - tri.pp) + ((t * wp + half) >> f);
        let kq = (oq - tri.pq) + ((t * wq + half) >> f);
        let u = tri.e1p * kq - tri.e1q * kp;
        let v = tri.e2q * kp - tri.e2p * kq;
        if (u | v) < 0 || u as u64 + v as u64 > uv_max {
            return None;
        }
        Some(TriHit { t, u: u.checked_shr(self.e).unwrap_or(0), v: v.checked_shr(self.e).unwrap_or(0) })
    }

    /// The early-out traversal on the i64 path: near child first, far child pushed, a node
    /// skipped when lower_t(its tmin) > best t (tested as tmin > `prune_limit`). It differs
    /// from `walk` only where the outcome cannot:
    /// - plane distances are not saturated to [−1, 2^(n+1)] except the far child's start at
    ///   2^(n+1): tmin ≥ 0 and tmax ≤ box_exit ≤ 2^(n+1), so min(tmax, ·) and max(tmin, ·) see
    ///   the same values, except a far start above 2^(n+1) against tmax = 2^(n+1);
    /// - a near child is not tested for pruning: its tmin is its parent's, with the same best;
    /// - a triangle test gets the window [max(1, lower_t(leaf tmin)), best t]: `Closest`
    ///   would not accept a t outside it either.
    fn trace_narrow(&self, fs: &FastScene, nr: &NarrowRay) -> (Option<Hit>, TraversalStats) {
        let mut stats = TraversalStats::default();
        let mut best: Option<Hit> = None;
        let tmax0 = nr.tmax0;
        if tmax0 < 0 {
            return (best, stats);
        }
        let (mut best_t, mut prune_above) = (i64::MAX, i64::MAX);
        // Uninitialised: zeroing it per ray would cost more than a short traversal.
        let mut stack = [const { MaybeUninit::<(u32, i64, i64)>::uninit() }; 256];
        let mut sp = 0usize;
        let (mut node, mut tmin, mut tmax) = (0u32, 0i64, tmax0);
        loop {
            stats.nodes += 1;
            let nd = &fs.nodes[node as usize];
            if nd.kind < LEAF {
                let ax = &nr.axes[nd.kind as usize];
                let s = ax.neg as usize;
                let near_max = tmax.min(ax.plane_t(nd.clips[s], self.c));
                let far_min = tmin.max(ax.plane_t(nd.clips[1 - s], self.c).min(self.t_sat));
                let (near, far) = (nd.link + s as u32, nd.link + 1 - s as u32);
                if tmin <= near_max {
                    if far_min <= tmax {
                        stack[sp].write((far, far_min, tmax));
                        sp += 1;
                        stats.max_stack = stats.max_stack.max(sp as u32);
                    }
                    (node, tmax) = (near, near_max);
                    continue;
                }
                if far_min <= tmax && far_min <= prune_above {
                    (node, tmin) = (far, far_min);
                    continue;
                }
            } else {
                let lo = lower_t(tmin).max(1);
                let uv_max = 1u64.checked_shl(self.e + self.f).unwrap_or(u64::MAX);
                let tris = &fs.tris[nd.link as usize..(nd.link + nd.kind - LEAF) as usize];
                for ft in tris {
                    let Some(h) = self.intersect_narrow(&ft.tri, nr, lo, best_t.min(self.t_sat - 1), uv_max) else {
                        continue;
                    };
                    if best.is_none_or(|b| (h.t, ft.id) < (b.t, b.tri)) {
                        best = Some(Hit { tri: ft.id, t: h.t, u: h.u, v: h.v });
                        (best_t, prune_above) = (h.t, prune_limit(h.t));
                    }
                }
                stats.tri_tests += tris.len() as u32;
            }
            // Pop the next entry that is not pruned.
            loop {
                if sp == 0 {
                    return (best, stats);
                }
                sp -= 1;
                // SAFETY: entries below the stack pointer were written by a push.
                (node, tmin, tmax) = unsafe { stack[sp].assume_init() };
                if tmin <= prune_above {
                    break;
                }
            }
        }
    }
}

/// The largest tmin with lower_t(tmin) ≤ best_t (for best_t ≥ 0): lower_t(x) =
/// ceil(63x/64) − 8, so lower_t(x) ≤ b ⟺ 63x ≤ 64(b + 8).
#[inline]
fn prune_limit(best_t: i64) -> i64 {
    64 * (best_t + 8) / 63
}

/// floor(a / b) for 0 < a < 2^63, 0 < b < 2^53, a / b ≤ 2^50: the f64 quotient is within
/// 2^−2 of a/b (two roundings of at most 2^−53 relative), so its truncation q is off by at
/// most one, and the remainder a − q·b ∈ [−b, 2b) (exact in wrapping i64) says which way.
#[inline(always)]
fn div_floor(a: i64, b: i64) -> i64 {
    // SAFETY: a / b is finite and in [0, 2^50] (rounded), so it converts without saturation (which
    // `as` would check for with compares on every triangle test).
    let q: i64 = unsafe { (a as f64 / b as f64).to_int_unchecked() };
    let r = a.wrapping_sub(q.wrapping_mul(b));
    q - (r < 0) as i64 + (r >= b) as i64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::ray::quantize_direction;
    use proptest::prelude::*;

    /// Width sets at the edges of `narrow_widths` (n, m), with T, C and E drawn to fit.
    fn widths() -> impl Strategy<Value = Golden> {
        prop_oneof![Just((29u32, 32u32)), Just((40, 21)), Just((4, 8)), Just((30, 31)), Just((16, 16)), Just((33, 28))]
            .prop_flat_map(|(n, m)| {
                (Just(n), Just(m), 0..=m - 2, 0..=(64 - m).min(62 - n), 0..=(125 - n - (m - 1)).min(120))
            })
            .prop_map(|(n, m, t, c, e)| Golden {
                n,
                f: m - 1,
                t,
                c,
                e,
                box_hi: [(1 << n) - 1; 3],
                t_sat: 1 << (n + 1),
                fast: None,
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20000))]

        #[test]
        fn div_floor_is_the_exact_floor(b in 1i64..1 << 53, q in 0i64..=1 << 50, r in any::<u64>()) {
            // a = q·b + r′ with 0 ≤ r′ < b, kept below 2^63.
            let q = q.min((i64::MAX - b) / b);
            let a = q * b + (r % b as u64) as i64;
            prop_assert_eq!(div_floor(a, b), q);
            prop_assert_eq!(div_floor(q * b, b), q);
        }

        #[test]
        fn prune_limit_is_the_last_tmin_not_pruned(b in 0i64..1 << 42) {
            let x = prune_limit(b);
            prop_assert!(lower_t(x) <= b && lower_t(x + 1) > b);
        }

        /// `intersect_narrow` against `intersect` on triangles and rays anywhere inside the
        /// bounds of the i64 path (mostly misses, at extreme magnitudes) and on triangles of
        /// random vertices with rays aimed at them (hits and near misses), in random windows.
        #[test]
        fn narrow_intersect_is_intersect(
            g in widths(),
            raw in prop::array::uniform16(any::<u64>()),
            aim in (0.0f64..1.0, -0.1f64..1.1, -0.1f64..1.1),
            window in (any::<u64>(), any::<u64>()),
        ) {
            let (b, s) = (1i64 << g.n, 1i64 << g.f);
            let pick = |i: usize, lo: i64, hi: i64| lo + (raw[i] % (hi - lo) as u64) as i64;
            let (tri, ray) = if aim.0 < 0.5 {
                let small = |i: usize| pick(i, 1 - s, s);
                let (r, pp, pq, d) = ((raw[0] % 3) as u8, pick(1, 0, b), pick(2, 0, b), pick(3, 1 - 3 * b, 3 * b));
                let tri = AccelTri { r, pp, pq, d, np: small(4), nq: small(5), e1p: small(6), e1q: small(7), e2p: small(8), e2q: small(9) };
                (tri, g.ray([pick(10, 0, b), pick(11, 0, b), pick(12, 0, b)], [small(13), small(14), small(15)]))
            } else {
                let v: [[i64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|k| pick(3 * i + k, 0, b)));
                let Some(q) = crate::scene::accel::quantize(&v, g.f, g.e) else { return Ok(()) };
                let o = [pick(9, 0, b), pick(10, 0, b), pick(11, 0, b)];
                let edge = |i: usize, k: usize| (v[i][k] - v[0][k]) as f64;
                let d: [f64; 3] = std::array::from_fn(|k| (v[0][k] - o[k]) as f64 + aim.1 * edge(1, k) + aim.2 * edge(2, k));
                let w = quantize_direction(crate::model::ray::normalize(d), g.f);
                prop_assume!(w != [0; 3]);
                (q.tri, g.ray(o, w))
            };
            let nr = NarrowRay::new(&g, &ray).expect("in bounds");
            let lo = 1 + (window.0 % g.t_sat as u64) as i64;
            let hi = (window.1 % g.t_sat as u64) as i64;
            let uv_max = 1u64.checked_shl(g.e + g.f).unwrap_or(u64::MAX);
            let want = g.intersect(&tri, &ray);
            prop_assert_eq!(g.intersect_narrow(&tri, &nr, 1, g.t_sat - 1, uv_max), want);
            prop_assert_eq!(g.intersect_narrow(&tri, &nr, lo, hi, uv_max), want.filter(|h| (lo..=hi).contains(&h.t)));
        }
    }
}
