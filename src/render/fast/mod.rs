//! The golden model's closest hit, fast: `FastGolden::trace` gives what `Golden::trace` gives,
//! bit for bit (the tests here and in `tracer` check it against the reference), by
//! - an early out: a node whose entry distance proves it cannot hold a better accepted hit
//!   is skipped (exact because of `lower_t`, docs/ARITHMETIC.md);
//! - an i64 path (`trace_narrow`) where the widths and the scene's values bound every value,
//!   over a copy of the BIH laid out for speed;
//! - primary rays traced in packets (`packet`: 16 lanes with AVX-512, 8 with AVX2, whichever
//!   the CPU has, chosen at run time) after eight rays are quantised at once (`quantize8`).
//!
//! The golden model itself (`model::golden`) stays the plain reference.

mod packet;
mod quantize8;

pub(crate) use packet::{Kernel, LANES};
pub(crate) use quantize8::quantize_ray8;

use crate::model::golden::{Golden, GridRay, Hit, TraversalStats, TriHit, lower_t};
use crate::params::Params;
use crate::scene::Scene;
use crate::scene::accel::AccelTri;
use crate::scene::bih::Node;
use std::mem::MaybeUninit;

/// Which code traces: every path gives the reference's answer, bit for bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum GoldenPath {
    /// The fastest the CPU, the scene and the widths allow (the default).
    Auto,
    /// `model::golden` itself: i128 arithmetic, the plain walk.
    Reference,
    /// The i64 path, a ray at a time, no vector instructions (what a CPU without AVX2 runs).
    Scalar,
    /// AVX2 packets of 8 rays, eight rays quantised at once (and the i64 path for rays that
    /// do not fit a packet).
    Avx2,
    /// AVX-512 packets of 16 rays, eight rays quantised at once (and the i64 path for rays
    /// that do not fit a packet).
    Avx512,
}

impl GoldenPath {
    pub const ALL: [GoldenPath; 5] =
        [GoldenPath::Auto, GoldenPath::Reference, GoldenPath::Scalar, GoldenPath::Avx2, GoldenPath::Avx512];

    pub fn name(self) -> &'static str {
        match self {
            GoldenPath::Auto => "auto",
            GoldenPath::Reference => "reference",
            GoldenPath::Scalar => "scalar",
            GoldenPath::Avx2 => "avx2",
            GoldenPath::Avx512 => "avx512",
        }
    }

    /// The path `$FXRT_GOLDEN_PATH` names (auto when unset); an error names the variable.
    pub fn from_env() -> crate::error::Result<GoldenPath> {
        match std::env::var("FXRT_GOLDEN_PATH") {
            Err(_) => Ok(GoldenPath::Auto),
            Ok(v) => GoldenPath::ALL.into_iter().find(|p| p.name() == v).ok_or_else(|| {
                crate::error::Error::new(
                    "$FXRT_GOLDEN_PATH",
                    format!("'{v}' is not a path: use auto, reference, scalar, avx2 or avx512"),
                )
            }),
        }
    }
}

/// The golden model of one scene with its fast layout (when the scene has one).
#[derive(Debug)]
pub struct FastGolden<'a> {
    pub scene: &'a Scene,
    pub golden: Golden,
    layout: Option<FastScene>,
    /// The instruction set `trace_packet` runs on, when the layout exists and the CPU and
    /// widths suit one.
    kernel: Option<Kernel>,
}

impl<'a> FastGolden<'a> {
    /// The fastest path (`GoldenPath::Auto`), or the one `$FXRT_GOLDEN_PATH` forces when it
    /// names one this machine and scene can run (else the fastest: `path_available` tells).
    pub fn new(scene: &'a Scene) -> Self {
        Self::with_path(scene, GoldenPath::from_env().unwrap_or(GoldenPath::Auto))
    }

    /// Whether `path` can run on this CPU for `scene` (reference, and auto, always can).
    pub fn path_available(scene: &Scene, path: GoldenPath) -> bool {
        match path {
            GoldenPath::Auto | GoldenPath::Reference => true,
            GoldenPath::Scalar => FastScene::new(scene).is_some(),
            GoldenPath::Avx2 => FastScene::new(scene).is_some() && Kernel::Avx2.available(&scene.params),
            GoldenPath::Avx512 => FastScene::new(scene).is_some() && Kernel::Avx512.available(&scene.params),
        }
    }

    /// The model tracing by `path`; a path that cannot run here falls back to the fastest
    /// (check `path_available` first to know).
    pub fn with_path(scene: &'a Scene, path: GoldenPath) -> Self {
        // The layout is built once; a forced kernel this CPU or these widths cannot run falls
        // back to the fastest (what `path_available` tells beforehand).
        let layout = if path == GoldenPath::Reference { None } else { FastScene::new(scene) };
        let forced = match path {
            GoldenPath::Avx2 => Some(Kernel::Avx2),
            GoldenPath::Avx512 => Some(Kernel::Avx512),
            _ => None,
        };
        let kernel = match path {
            _ if layout.is_none() => None,
            GoldenPath::Reference | GoldenPath::Scalar => None,
            _ => forced.filter(|k| k.available(&scene.params)).or_else(|| Kernel::best(&scene.params)),
        };
        FastGolden { scene, golden: Golden::new(scene), layout, kernel }
    }

    /// The path that runs: reference, scalar, avx2 or avx512.
    pub fn path(&self) -> GoldenPath {
        match (&self.layout, self.kernel) {
            (None, _) => GoldenPath::Reference,
            (Some(_), None) => GoldenPath::Scalar,
            (Some(_), Some(Kernel::Avx2)) => GoldenPath::Avx2,
            (Some(_), Some(Kernel::Avx512)) => GoldenPath::Avx512,
        }
    }

    /// `Golden::trace`'s answer, bit for bit; the statistics count only what was visited.
    pub fn trace(&self, ray: &GridRay) -> (Option<Hit>, TraversalStats) {
        // The i64 ray only where the layout exists: its widths (`narrow_widths`) are what keep
        // NarrowRay's shifts by C in range (C = 64 is a valid parameter).
        if let Some(fs) = &self.layout
            && let Some(nr) = NarrowRay::new(&self.golden, ray)
        {
            return trace_narrow(&self.golden, fs, &nr);
        }
        self.golden.trace_culled(self.scene, ray)
    }

    /// Whether the i64 path applies to the scene (a ray must also fit `NarrowRay`).
    pub fn has_narrow_path(&self) -> bool {
        self.layout.is_some()
    }

    /// The instruction set `trace_packet` runs on, if any.
    pub(crate) fn kernel(&self) -> Option<Kernel> {
        self.kernel
    }

    /// Whether `ray` takes the i64 path, as every ray of a packet must.
    pub(crate) fn fits(&self, ray: &GridRay) -> bool {
        NarrowRay::fits(&self.golden, ray)
    }

    /// `trace` of up to LANES rays at once (each must `fit`); only when `kernel()` is some.
    pub(crate) fn trace_packet(&self, rays: &[GridRay]) -> [Option<Hit>; LANES] {
        // `Kernel::trace` runs AVX code: `with_path` chose the kernel only where it is available.
        match (&self.layout, self.kernel) {
            (Some(fs), Some(kernel)) => kernel.trace(&self.golden, fs, rays),
            _ => panic!("packet tracing needs AVX2 or AVX-512 and the i64 layout"),
        }
    }
}

// The i64 path (`trace_narrow`). It computes every value `Golden::trace` computes, with the
// same formulas, in i64 instead of i128 where the widths bound them (`narrow_widths`), and
// walks a copy of the BIH laid out for speed. With B = 2^n, S = 2^F and, checked per scene and per
// ray, 0 ≤ O, pp, pq, clip, box_hi < B, |d| < 3B, |np|, |nq|, |e..|, |ω| < S, |inv| < 2^(F+C):
// - num: |(d − O_r)·S| < 4BS, |O_p·np| + |O_q·nq| < 2BS, so |num| < 2^(n+F+3) ≤ 2^63 (n+m ≤ 61);
// - den: |ω_p·np + ω_q·nq| + S/2 < 2S² ≤ 2^63 (m ≤ 32), so |den| < 3S and (hi+1)·|den| < 6BS;
// - t < 2B, so |t·ω| < 2BS, |kp|, |kq| < 3B and |u|, |v| < 6BS < 2^63;
// - traversal: |(P − O)·inv_hi| < B·2^F and |(P − O)·inv_lo| < 2^(n+C) ≤ 2^62 (see NarrowAxis).

fn narrow_widths(p: &Params) -> bool {
    p.n + p.m <= 61 && p.m <= 32 && p.m + p.c <= 64 && p.n + p.c <= 62
}

/// The BIH with each leaf's triangles copied next to each other in leaf order.
struct FastScene {
    nodes: Vec<FastNode>,
    tris: Vec<FastTri>,
}

const LEAF: u32 = 3;

struct FastNode {
    clips: [i64; 2],
    /// Inner node: children link and link + 1. Leaf: tris[link..link + kind − LEAF].
    link: u32,
    /// The split axis of an inner node (< LEAF), or LEAF + the leaf's triangle count.
    kind: u32,
}

struct FastTri {
    tri: AccelTri,
    /// Its number in the scene's triangle table.
    id: u32,
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
        Some(FastScene { nodes, tris })
    }
}

/// `intersect` in i64, also rejecting every t outside [lo, hi] (1 ≤ lo, hi < 2^(n+1))
/// before dividing, by comparing products; inside the window it returns what `intersect`
/// does. `uv_max` is 2^(E+F) as a u64 (saturated: u + v < 2^64 never exceeds it then).
#[inline(always)]
fn intersect_narrow(g: &Golden, tri: &AccelTri, ray: &NarrowRay, lo: i64, hi: i64, uv_max: u64) -> Option<TriHit> {
    // r < 3 was checked by FastScene::new; `& 3` spares the bounds check.
    let [or, op, oq, wr, wp, wq] = ray.rows[tri.r as usize & 3];
    let (f, half) = (g.f, 1i64 << (g.f - 1));
    let den = (wr + ((wp * tri.np + wq * tri.nq + half) >> f)) >> g.t;
    let num = (((tri.d - or) << f) - op * tri.np - oq * tri.nq) >> g.t;
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
    Some(TriHit { t, u: u.checked_shr(g.e).unwrap_or(0), v: v.checked_shr(g.e).unwrap_or(0) })
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
fn trace_narrow(g: &Golden, fs: &FastScene, nr: &NarrowRay) -> (Option<Hit>, TraversalStats) {
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
            let near_max = tmax.min(ax.plane_t(nd.clips[s], g.c));
            let far_min = tmin.max(ax.plane_t(nd.clips[1 - s], g.c).min(g.t_sat));
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
            let uv_max = 1u64.checked_shl(g.e + g.f).unwrap_or(u64::MAX);
            let tris = &fs.tris[nd.link as usize..(nd.link + nd.kind - LEAF) as usize];
            for ft in tris {
                let Some(h) = intersect_narrow(g, &ft.tri, nr, lo, best_t.min(g.t_sat - 1), uv_max) else {
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

/// A grid ray in the i64 form the i64 path reads (its bounds are proved above): rows[r] = [O_r, O_p, O_q, ω_r, ω_p, ω_q] for projection axis r.
struct NarrowRay {
    rows: [[i64; 6]; 4],
    axes: [NarrowAxis; 3],
    /// `Golden::box_exit`.
    tmax0: i64,
}

/// One axis for plane distances: inv = inv_hi·2^C + inv_lo with 0 ≤ inv_lo < 2^C, so
/// floor((P − O)·inv / 2^C) = (P − O)·inv_hi + floor((P − O)·inv_lo / 2^C), all in i64.
struct NarrowAxis {
    o: i64,
    inv_hi: i64,
    inv_lo: i64,
    /// inv < 0: the right child (link + 1) is the near one.
    neg: bool,
}

impl NarrowAxis {
    /// `Golden::plane_t` before saturation, for a plane in [0, 2^n).
    #[inline(always)]
    fn plane_t(&self, plane: i64, c: u32) -> i64 {
        let d = plane - self.o;
        d * self.inv_hi + ((d * self.inv_lo) >> c)
    }
}

impl NarrowRay {
    /// The ray is inside the bounds of the fast path: 0 ≤ O < 2^n, |ω| < 2^F and |inv| <
    /// 2^(F+C) (what `Golden::ray` makes; < 2^63 as m + C ≤ 64).
    #[inline]
    fn fits(g: &Golden, ray: &GridRay) -> bool {
        ray.o.iter().all(|&o| (0..1i64 << g.n).contains(&o))
            && ray.w.iter().all(|&w| w.unsigned_abs() < 1 << g.f)
            && ray.inv.iter().all(|&i| i.unsigned_abs() < 1 << (g.f + g.c))
    }

    /// None when the ray does not fit, or C is too wide for an i64 shift (the fast layout's
    /// widths have C ≤ 62 − n).
    fn new(g: &Golden, ray: &GridRay) -> Option<NarrowRay> {
        if g.c > 62 || !Self::fits(g, ray) {
            return None;
        }
        let axes: [NarrowAxis; 3] = std::array::from_fn(|k| {
            let inv = ray.inv[k] as i64;
            NarrowAxis { o: ray.o[k], inv_hi: inv >> g.c, inv_lo: inv & ((1 << g.c) - 1), neg: inv < 0 }
        });
        let exit = |k: usize| axes[k].plane_t(if axes[k].neg { 0 } else { g.box_hi[k] }, g.c).clamp(-1, g.t_sat);
        let rows = std::array::from_fn(|r| {
            let (r, p, q) = crate::model::golden::perm(r as u8 % 3);
            [ray.o[r], ray.o[p], ray.o[q], ray.w[r], ray.w[p], ray.w[q]]
        });
        Some(NarrowRay { rows, tmax0: exit(0).min(exit(1)).min(exit(2)), axes })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::ray::quantize_direction;
    use crate::params::Params;
    use proptest::prelude::*;

    /// Width sets at the edges of `narrow_widths` (n, m), with T, C and E drawn to fit.
    fn widths() -> impl Strategy<Value = Golden> {
        prop_oneof![Just((29u32, 32u32)), Just((40, 21)), Just((4, 8)), Just((30, 31)), Just((16, 16)), Just((33, 28))]
            .prop_flat_map(|(n, m)| {
                (Just(n), Just(m), 0..=m - 2, 0..=(64 - m).min(62 - n), 0..=(125 - n - (m - 1)).min(120))
            })
            .prop_map(|(n, m, t, c, e)| Golden { n, f: m - 1, t, c, e, box_hi: [(1 << n) - 1; 3], t_sat: 1 << (n + 1) })
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
            prop_assert_eq!(intersect_narrow(&g, &tri, &nr, 1, g.t_sat - 1, uv_max), want);
            prop_assert_eq!(intersect_narrow(&g, &tri, &nr, lo, hi, uv_max), want.filter(|h| (lo..=hi).contains(&h.t)));
        }
    }

    /// C = 64 is valid (with small n and m) but no i64 shift: the fast path must fall back
    /// to the model without evaluating its i64 ray (a debug build overflowed in `inv >> C`).
    #[test]
    fn the_widest_c_falls_back_to_the_model() {
        for (n, m) in [(4, 8), (20, 40)] {
            let params = Params { n, m, c: 64, ..Params::default() };
            let tris = vec![[[0., 0., 0.], [1., 0., 0.], [0., 1., 1.]], [[0., 0., 1.], [1., 1., 0.], [1., 0., 1.]]];
            let s = crate::scene::Scene::build("wide c", tris, &params).unwrap();
            let fast = FastGolden::new(&s);
            assert!(!fast.has_narrow_path());
            let g = &fast.golden;
            let hi = (1i64 << n) - 1;
            for (o, d) in
                [([hi / 3, hi / 4, 0], [0.1, 0.2, 1.0]), ([hi, hi, hi], [-0.5, -0.6, -0.7]), ([0; 3], [1.0, 0.0, 0.0])]
            {
                let ray = g.ray(o, quantize_direction(crate::model::ray::normalize(d), g.f));
                assert!(NarrowRay::new(g, &ray).is_none());
                assert_eq!(fast.trace(&ray).0, g.trace(&s, &ray).0);
            }
        }
    }

    proptest::proptest! {
        /// The split plane distance and box exit of `NarrowRay` are `plane_t` and `box_exit`.
        #[test]
        fn narrow_planes_are_plane_t(
            set in 0usize..3,
            o in proptest::array::uniform3(0.0f64..1.0),
            w in proptest::array::uniform3(-1.0f64..1.0),
            plane in 0.0f64..1.0,
            k in 0usize..3,
        ) {
            let (n, m, c) = [(29, 32, 16), (40, 21, 3), (16, 16, 46)][set];
            let params = Params { n, m, c, ..Params::default() };
            let s = crate::scene::Scene::build("cube", vec![[[0., 0., 0.], [1., 0., 0.], [0., 1., 1.]]], &params).unwrap();
            let g = Golden::new(&s);
            let b = (1i64 << g.n) as f64;
            let ray = g.ray(o.map(|x| (x * b) as i64), quantize_direction(w, g.f));
            let nr = NarrowRay::new(&g, &ray).unwrap();
            let plane = (plane * b) as i64;
            proptest::prop_assert_eq!(nr.axes[k].plane_t(plane, g.c).clamp(-1, g.t_sat), g.plane_t(&ray, k, plane));
            proptest::prop_assert_eq!(nr.tmax0, g.box_exit(&ray));
        }
    }
}
