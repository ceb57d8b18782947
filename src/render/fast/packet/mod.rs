//! Primary rays in packets of sixteen: one walk of the BIH for a packet, each ray (lane) with
//! its own interval, best hit and pruning. This is `trace_narrow` with every value of a ray in
//! one lane, and gives each ray the same answer: a lane's interval at a node is computed along
//! the same path by the same formulas, it takes part in a node exactly when its interval is
//! non-empty and not pruned by its own best, and the visiting order (near first for most
//! lanes) decides nothing, because the answer is the smallest (t, triangle) over accepted hits
//! and pruning only skips nodes that cannot improve it. Neighbouring primary rays visit nearly
//! the same nodes, so a packet costs little more than one ray.
//!
//! The walk is written once (`packet_walk!`) over a small set of lane-wise operations that each
//! instruction set defines with the same names: `avx512` (a value in two 512-bit registers, a
//! lane mask in a `u32`) and `avx2` (a value in four 256-bit registers, a lane mask in the sign
//! bits of four registers; what AVX2 lacks for 64-bit lanes, such as min, max, arithmetic
//! shifts and i64 ↔ f64 conversions, is built from what it has). Products use 32 × 32 → 64-bit
//! lane multiplies (`mul32`), so every factor must fit an i32: with n ≤ 29, m ≤ 32, C ≤ 31
//! the plane offsets (< 2^n), inv_hi (< 2^(m−1)), inv_lo (< 2^C), ω, np, nq, e.. (< 2^F),
//! t (< 2^(n+1)) and kp, kq (< 3·2^n) do.

use crate::model::golden::{Golden, GridRay, Hit};
use crate::params::Params;
use crate::render::fast::FastScene;

/// Rays per packet, on every instruction set.
pub const LANES: usize = 16;

/// An instruction set the packets run on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    Avx512,
    Avx2,
}

impl Kernel {
    /// Whether this CPU has the instructions.
    pub fn cpu_has(self) -> bool {
        #[cfg(target_arch = "x86_64")]
        return match self {
            Kernel::Avx512 => is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512dq"),
            Kernel::Avx2 => is_x86_feature_detected!("avx2"),
        };
        #[cfg(not(target_arch = "x86_64"))]
        false
    }

    /// Whether this CPU has the instructions and the widths keep every factor of `mul32` in an i32.
    pub fn available(self, p: &Params) -> bool {
        self.cpu_has() && p.n <= 29 && p.m <= 32 && p.c <= 31
    }

    /// The fastest kernel available, if any.
    pub fn best(p: &Params) -> Option<Kernel> {
        [Kernel::Avx512, Kernel::Avx2].into_iter().find(|k| k.available(p))
    }

    /// Hits of up to LANES rays, each fitting `NarrowRay`; `self.available` must have held.
    pub(super) fn trace(self, g: &Golden, fs: &FastScene, rays: &[GridRay]) -> [Option<Hit>; LANES] {
        assert!(!rays.is_empty() && rays.len() <= LANES, "a packet holds 1..={LANES} rays");
        #[cfg(target_arch = "x86_64")]
        match self {
            // SAFETY: `FastGolden` holds a kernel only after `available` found its instructions.
            Kernel::Avx512 => unsafe { avx512::trace(g, fs, rays) },
            // SAFETY: as above.
            Kernel::Avx2 => unsafe { avx2::trace(g, fs, rays) },
        }
        #[cfg(not(target_arch = "x86_64"))]
        unreachable!("packets need x86-64 ({self:?} on {} rays of {g:?} over {fs:?})", rays.len())
    }
}

/// The walk of one packet, as a function `walk` with `$features` enabled (and `trace`, LANES
/// rays as packets of PACKET), over the lane-wise operations in scope where it expands:
/// - W (a value per lane), Mask (a bit per lane), `to_w`, `to_a`, `splat`, `splat32` (a
///   factor for `mul32`);
/// - add, sub, min, max, bit_and, bit_or, xor; abs_by (|a| where b has a's sign); mul32
///   (signed low 32 × low 32 → 64); mul_lo32 (a·b mod 2^64 for 0 ≤ a < 2^32); div_f64
///   (floor(a/b) off by at most one for 0 ≤ a, b < 2^63; ≥ 2^32 − 1 or negative when b = 0 or
///   a/b ≥ 2^32 − 1); sign (−1 or 0); div64 (floor(a/64) for a ≥ 0); sra, sra_small (for
///   |a| < 2^62), sll (by a run-time count);
/// - le, lt, ge, le_unsigned, negative (→ Mask); blend (b in the mask's lanes); the mask
///   operations both, either, any, count, all_if, first.
#[cfg(target_arch = "x86_64")]
macro_rules! packet_walk {
    ($features:literal) => {
        /// LANES rays as packets of PACKET.
        #[target_feature(enable = $features)]
        pub(super) fn trace(g: &Golden, fs: &FastScene, rays: &[GridRay]) -> [Option<Hit>; LANES] {
            let mut hits = [None; LANES];
            for (c, chunk) in rays.chunks(PACKET).enumerate() {
                hits[c * PACKET..(c + 1) * PACKET].copy_from_slice(&walk(g, fs, chunk));
            }
            hits
        }

        #[target_feature(enable = $features)]
        fn walk(g: &Golden, fs: &FastScene, rays: &[GridRay]) -> [Option<Hit>; PACKET] {
            // The rays lane by lane (missing lanes repeat ray 0), inv split as in NarrowAxis;
            // each array padded to four so that an index `& 3` needs no bounds check. Built a
            // value at a time: arrays of whole arrays would be copied with memcpy per packet.
            let lanes = |v: fn(&GridRay) -> [i64; 3], k: usize| -> W {
                to_w(std::array::from_fn(|l| v(rays.get(l).unwrap_or(&rays[0]))[k]))
            };
            let (mut o, mut w, mut inv_hi, mut inv_lo) = ([splat(0); 4], [splat(0); 4], [splat(0); 3], [splat(0); 3]);
            let mut neg = [all_if(false); 3];
            for k in 0..3 {
                o[k] = lanes(|r| r.o, k);
                w[k] = lanes(|r| r.w, k);
                let inv = lanes(|r| r.inv.map(|i| i as i64), k);
                inv_hi[k] = sra(inv, g.c);
                inv_lo[k] = bit_and(inv, splat((1 << g.c) - 1));
                neg[k] = negative(inv);
            }
            // (r, p, q) for each projection axis r (r < 3; row 3 unused).
            let axes: [[usize; 3]; 4] = std::array::from_fn(|r| {
                let (r, p, q) = crate::model::golden::perm(r as u8 % 3);
                [r as usize, p as usize, q as usize]
            });
            let plane_t = |k: usize, p: W| {
                let d = sub(p, o[k]);
                // |d·inv_lo| < 2^(n+C) ≤ 2^60.
                add(mul32(d, inv_hi[k]), sra_small(mul32(d, inv_lo[k]), g.c))
            };
            let (zero, one, half) = (splat(0), splat(1), splat(1 << (g.f - 1)));
            let (t_sat, t_top, min_v, max_v) = (splat(g.t_sat), splat(g.t_sat - 1), splat(i64::MIN), splat(i64::MAX));
            // box_exit: the plane each lane leaves the box through, saturated to [−1, 2^(n+1)];
            // missing lanes get −1 (an empty interval).
            let exit = |k: usize| max(min(plane_t(k, blend(neg[k], splat(g.box_hi[k]), zero)), t_sat), splat(-1));
            let tmax0 = blend(first(rays.len()), splat(-1), min(min(exit(0), exit(1)), exit(2)));
            let uv_max = splat(1u64.checked_shl(g.e + g.f).unwrap_or(u64::MAX) as i64);
            // For x ≥ 0: every tmin is (it starts at 0 and only grows).
            let lower_t = |x: W| sub(sub(x, div64(x)), splat(8));
            // The divider's precision drop, skipped when there is none (the default T = 0).
            let drop_t = |x: W| if g.t == 0 { x } else { sra(x, g.t) };
            let (mut best_t, mut best_id, mut best_u, mut best_v) = (max_v, max_v, zero, zero);
            // Per lane, a bound P ≥ prune_limit(best t) (the largest tmin with lower_t(tmin) ≤
            // best t): a node with tmin > P cannot hold a better hit. With y = t + 8,
            // prune_limit = y + floor(y/63), and floor(y/63) ≤ Σ_{k=1..4} floor(y/64^k) + 6 for
            // y < 2^31 (t < 2^(n+1) ≤ 2^30): 1/63 = Σ 64^−k, the four floors lose < 4 and the
            // tail from k = 5 is < 2·64/63. A looser bound only visits a node more, never
            // changes a hit.
            let mut prune = max_v;
            let prune_bound = |t: W| {
                let y = add(t, splat(8));
                let (d1, d2) = (div64(y), div64(div64(y)));
                let (d3, d4) = (div64(d2), div64(div64(d2)));
                add(add(add(y, d1), add(d2, d3)), add(d4, splat(6)))
            };
            // Lanes that take part in a node: non-empty interval, not pruned by their best.
            let live = |iv: &Interval, prune: W| le(iv.tmin, min(iv.tmax, prune));

            // One spare slot: every inner node writes its second child, pushed or not.
            let mut stack = [const { MaybeUninit::<(Interval, u32)>::uninit() }; 257];
            let mut sp = 0;
            let (mut node, mut iv) = (0u32, Interval { tmin: zero, tmax: tmax0 });
            let mut act = live(&iv, prune);
            loop {
                let nd = &fs.nodes[node as usize];
                if any(act) && nd.kind < LEAF {
                    let a = nd.kind as usize;
                    let (d0, d1) = (plane_t(a, splat(nd.clips[0])), plane_t(a, splat(nd.clips[1])));
                    // Per lane: the near child's end bounds tmax, the far child's start (saturated)
                    // bounds tmin; which child is near is the lane's sign.
                    let left = Interval {
                        tmin: max(iv.tmin, blend(neg[a], min_v, min(d0, t_sat))),
                        tmax: min(iv.tmax, blend(neg[a], d0, max_v)),
                    };
                    let right = Interval {
                        tmin: max(iv.tmin, blend(neg[a], min(d1, t_sat), min_v)),
                        tmax: min(iv.tmax, blend(neg[a], max_v, d1)),
                    };
                    let (lm, rm) = (live(&left, prune), live(&right, prune));
                    let right_first = 2 * count(both(neg[a], act)) > count(act);
                    let (left, right) = ((nd.link, left, lm), (nd.link + 1, right, rm));
                    let (first, second) = if right_first { (right, left) } else { (left, right) };
                    // Without branches: the second child is written always and kept when both
                    // are taken; a node with no lanes left pops at the top of the loop.
                    let take_first = any(first.2);
                    stack[sp].write((second.1, second.0));
                    sp += (take_first && any(second.2)) as usize;
                    let k = all_if(take_first);
                    (node, act) = if take_first { (first.0, first.2) } else { (second.0, second.2) };
                    iv = Interval {
                        tmin: blend(k, second.1.tmin, first.1.tmin),
                        tmax: blend(k, second.1.tmax, first.1.tmax),
                    };
                    continue;
                } else if any(act) {
                    let lo = max(lower_t(iv.tmin), one);
                    for ft in &fs.tris[nd.link as usize..(nd.link + nd.kind - LEAF) as usize] {
                        let tri = &ft.tri;
                        let [r, p, q] = axes[tri.r as usize & 3].map(|k| k & 3);
                        let (or, op, oq, wr, wp, wq) = (o[r], o[p], o[q], w[r], w[p], w[q]);
                        let (np, nq) = (splat32(tri.np), splat32(tri.nq));
                        let den = drop_t(add(wr, sra(add(add(mul32(wp, np), mul32(wq, nq)), half), g.f)));
                        let num = drop_t(sub(sll(sub(splat(tri.d), or), g.f), add(mul32(op, np), mul32(oq, nq))));
                        let signs = both(act, ge(xor(num, den), zero));
                        if !any(signs) {
                            continue;
                        }
                        // floor(a / b) as in `div_floor`. A lane with b = 0 or a / b ≥ 2^32 − 2
                        // gets a t far outside [lo, hi] and fails the window, as the divider must.
                        // |num| and |den| in the lanes where their signs agree (garbage elsewhere).
                        let (a_, b_) = (abs_by(num, den), abs_by(den, den));
                        let q = div_f64(a_, b_);
                        let r = sub(a_, mul_lo32(q, b_));
                        let t = add(add(q, sign(r)), blend(ge(r, b_), zero, one));
                        let ok = both(both(signs, ge(t, lo)), le(t, min(best_t, t_top)));
                        if !any(ok) {
                            continue;
                        }
                        // |t·ω| < 2^(n+1+F) ≤ 2^61 where t is in the window (garbage elsewhere).
                        let k = |o: W, p: i64, w: W| add(sub(o, splat(p)), sra_small(add(mul32(t, w), half), g.f));
                        let (kp, kq) = (k(op, tri.pp, wp), k(oq, tri.pq, wq));
                        let u = sub(mul32(splat32(tri.e1p), kq), mul32(splat32(tri.e1q), kp));
                        let v = sub(mul32(splat32(tri.e2q), kp), mul32(splat32(tri.e2p), kq));
                        let inside = both(ge(bit_or(u, v), zero), le_unsigned(add(u, v), uv_max));
                        // t ≤ best t here, so (t, id) < best ⟺ t < best t or id < best id.
                        let id = splat(ft.id as i64);
                        let better = both(both(ok, inside), either(lt(t, best_t), lt(id, best_id)));
                        if !any(better) {
                            continue;
                        }
                        best_t = blend(better, best_t, t);
                        best_id = blend(better, best_id, id);
                        best_u = blend(better, best_u, u);
                        best_v = blend(better, best_v, v);
                        prune = blend(better, prune, prune_bound(t));
                    }
                }
                if sp == 0 {
                    break;
                }
                sp -= 1;
                // SAFETY: entries below the stack pointer were written by a push.
                (iv, node) = unsafe { stack[sp].assume_init() };
                act = live(&iv, prune);
            }
            let (t, id, u, v) = (to_a(best_t), to_a(best_id), to_a(best_u), to_a(best_v));
            let shr = |x: i64| x.checked_shr(g.e).unwrap_or(0);
            std::array::from_fn(|l| {
                (id[l] != i64::MAX).then(|| Hit { tri: id[l] as u32, t: t[l], u: shr(u[l]), v: shr(v[l]) })
            })
        }

        /// A lane's interval [tmin, tmax] at a node; empty (tmin > tmax) when it does not take part.
        #[derive(Clone, Copy)]
        struct Interval {
            tmin: W,
            tmax: W,
        }
    };
}

#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(target_arch = "x86_64")]
mod avx512;
