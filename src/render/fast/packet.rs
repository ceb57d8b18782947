//! Primary rays in packets of sixteen with AVX-512: one walk of the BIH for a packet, each
//! ray (lane) with its own interval, best hit and pruning. This is `trace_narrow`
//! with every value of a ray in one lane, and gives each ray the same answer: a lane's
//! interval at a node is computed along the same path by the same formulas, it takes part
//! in a node exactly when its interval is non-empty and not pruned by its own best, and the
//! visiting order (near first for most lanes) decides nothing, because the answer is the
//! smallest (t, triangle) over accepted hits and pruning only skips nodes that cannot
//! improve it. Neighbouring primary rays visit nearly the same nodes, so a packet costs
//! little more than one ray. Products use `_mm512_mul_epi32` (32 × 32 → 64 bits), so every
//! factor must fit an i32: with n ≤ 29, m ≤ 32, C ≤ 31 the plane offsets (< 2^n), inv_hi
//! (< 2^(m−1)), inv_lo (< 2^C), ω, np, nq, e.. (< 2^F), t (< 2^(n+1)) and kp, kq (< 3·2^n) do.

#[cfg(target_arch = "x86_64")]
pub(crate) use avx512::{LANES, available, trace};
#[cfg(not(target_arch = "x86_64"))]
pub(crate) use fallback::{LANES, available, trace};

#[cfg(target_arch = "x86_64")]
mod avx512 {
    use crate::model::golden::{Golden, GridRay, Hit};
    use crate::params::Params;
    use crate::render::fast::{FastScene, LEAF};
    use std::arch::x86_64::*;
    use std::mem::MaybeUninit;

    /// Registers per value: a packet has 8·N lanes.
    const N: usize = 2;
    pub const LANES: usize = 8 * N;
    /// A value per lane, and a bit per lane.
    type W = [__m512i; N];
    type Mask = u32;

    pub fn available(p: &Params) -> bool {
        let cpu = is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512dq");
        cpu && p.n <= 29 && p.m <= 32 && p.c <= 31
    }

    /// Hits of up to LANES rays; `available` must hold, and each ray fit `NarrowRay`.
    pub fn trace(g: &Golden, fs: &FastScene, rays: &[GridRay]) -> [Option<Hit>; LANES] {
        // SAFETY: `FastGolden::trace_packet` calls this only when `available` found AVX-512F and DQ.
        unsafe { trace_avx512(g, fs, rays) }
    }

    fn to_w(a: [i64; LANES]) -> W {
        // SAFETY: both are 8·N plain i64.
        unsafe { std::mem::transmute(a) }
    }

    fn to_a(w: W) -> [i64; LANES] {
        // SAFETY: as above.
        unsafe { std::mem::transmute(w) }
    }

    // Lane-wise operations: one AVX-512 instruction per register.
    macro_rules! lanewise {
        ($($name:ident($($arg:ident),*) = $op:expr;)*) => {$(
            #[inline]
            #[target_feature(enable = "avx512f,avx512dq")]
            fn $name($($arg: W),*) -> W {
                std::array::from_fn(|i| $op($($arg[i]),*))
            }
        )*};
    }
    lanewise! {
        add(a, b) = _mm512_add_epi64;
        sub(a, b) = _mm512_sub_epi64;
        min(a, b) = _mm512_min_epi64;
        max(a, b) = _mm512_max_epi64;
        bit_or(a, b) = _mm512_or_si512;
        xor(a, b) = _mm512_xor_si512;
        abs(a) = _mm512_abs_epi64;
        // Signed 32 × 32 → 64-bit products of the low halves.
        mul32(a, b) = _mm512_mul_epi32;
        // floor(a / b) up to one, in f64.
        div_f64(a, b) = |a, b| _mm512_cvttpd_epi64(_mm512_div_pd(_mm512_cvtepi64_pd(a), _mm512_cvtepi64_pd(b)));
        // a · b mod 2^64 for 0 ≤ a < 2^32, from the two 32-bit halves of b.
        mul_lo32(a, b) = |a, b| _mm512_add_epi64(_mm512_mul_epu32(a, b), _mm512_slli_epi64::<32>(_mm512_mul_epu32(a, _mm512_srli_epi64::<32>(b))));
        // −1 for a negative lane, else 0; and floor(a / 64).
        sign(a) = _mm512_srai_epi64::<63>;
        div64(a) = _mm512_srai_epi64::<6>;
    }

    macro_rules! compare {
        ($($name:ident = $op:ident;)*) => {$(
            #[inline]
            #[target_feature(enable = "avx512f,avx512dq")]
            fn $name(a: W, b: W) -> Mask {
                (0..N).fold(0, |m, i| m | ($op(a[i], b[i]) as Mask) << (8 * i))
            }
        )*};
    }
    compare! { le = _mm512_cmple_epi64_mask; lt = _mm512_cmplt_epi64_mask; ge = _mm512_cmpge_epi64_mask; le_unsigned = _mm512_cmple_epu64_mask; }

    #[inline]
    #[target_feature(enable = "avx512f,avx512dq")]
    fn splat(x: i64) -> W {
        [_mm512_set1_epi64(x); N]
    }

    /// For a factor of `mul32` (which reads the low 32 bits of a lane): one broadcast.
    #[inline]
    #[target_feature(enable = "avx512f,avx512dq")]
    fn splat32(x: i64) -> W {
        [_mm512_set1_epi32(x as i32); N]
    }

    /// `b` in the lanes of `m`, `a` elsewhere.
    #[inline]
    #[target_feature(enable = "avx512f,avx512dq")]
    fn blend(m: Mask, a: W, b: W) -> W {
        std::array::from_fn(|i| _mm512_mask_blend_epi64((m >> (8 * i)) as u8, a[i], b[i]))
    }

    /// Arithmetic (`sra`) or logical left (`sll`) shift of every lane by `s`.
    #[inline]
    #[target_feature(enable = "avx512f,avx512dq")]
    fn sra(a: W, s: u32) -> W {
        a.map(|x| _mm512_sra_epi64(x, _mm_set_epi64x(0, s as i64)))
    }

    #[inline]
    #[target_feature(enable = "avx512f,avx512dq")]
    fn sll(a: W, s: u32) -> W {
        a.map(|x| _mm512_sll_epi64(x, _mm_set_epi64x(0, s as i64)))
    }

    /// A lane's interval [tmin, tmax] at a node; empty (tmin > tmax) when it does not take part.
    #[derive(Clone, Copy)]
    struct Interval {
        tmin: W,
        tmax: W,
    }

    #[target_feature(enable = "avx512f,avx512dq")]
    fn trace_avx512(g: &Golden, fs: &FastScene, rays: &[GridRay]) -> [Option<Hit>; LANES] {
        // The rays lane by lane (missing lanes repeat ray 0), inv split as in NarrowAxis.
        let (mut o, mut w, mut inv) = ([[0; LANES]; 3], [[0; LANES]; 3], [[0; LANES]; 3]);
        for l in 0..LANES {
            let r = rays.get(l).unwrap_or(&rays[0]);
            for k in 0..3 {
                (o[k][l], w[k][l], inv[k][l]) = (r.o[k], r.w[k], r.inv[k] as i64);
            }
        }
        let (o, w, inv) = (o.map(to_w), w.map(to_w), inv.map(to_w));
        // [O_r, O_p, O_q, ω_r, ω_p, ω_q] for each projection axis r (r < 3; row 3 unused).
        let rows: [[W; 6]; 4] = std::array::from_fn(|r| {
            let (r, p, q) = crate::model::golden::perm(r as u8 % 3);
            [o[r], o[p], o[q], w[r], w[p], w[q]]
        });
        let inv_hi = inv.map(|i| sra(i, g.c));
        let inv_lo = inv.map(|i| i.map(|x| _mm512_and_si512(x, _mm512_set1_epi64((1 << g.c) - 1))));
        let neg: [Mask; 3] = inv.map(|i| (0..N).fold(0, |m, r| m | (_mm512_movepi64_mask(i[r]) as Mask) << (8 * r)));
        let plane_t = |k: usize, p: W| {
            let d = sub(p, o[k]);
            add(mul32(d, inv_hi[k]), sra(mul32(d, inv_lo[k]), g.c))
        };
        let (zero, one, half) = (splat(0), splat(1), splat(1 << (g.f - 1)));
        let (t_sat, t_top, min_v, max_v) = (splat(g.t_sat), splat(g.t_sat - 1), splat(i64::MIN), splat(i64::MAX));
        // box_exit: the plane each lane leaves the box through, saturated to [−1, 2^(n+1)];
        // missing lanes get −1 (an empty interval).
        let exit = |k: usize| max(min(plane_t(k, blend(neg[k], splat(g.box_hi[k]), zero)), t_sat), splat(-1));
        let tmax0 = blend(((1u64 << rays.len()) - 1) as Mask, splat(-1), min(min(exit(0), exit(1)), exit(2)));
        let uv_max = splat(1u64.checked_shl(g.e + g.f).unwrap_or(u64::MAX) as i64);
        let lower_t = |x: W| sub(sub(x, div64(x)), splat(8));
        let (mut best_t, mut best_id, mut best_u, mut best_v) = (max_v, max_v, zero, zero);
        // Lanes that take part in a node: non-empty interval, not pruned by their best.
        let live = |iv: &Interval, best_t: W| le(iv.tmin, iv.tmax) & le(lower_t(iv.tmin), best_t);

        // One spare slot: every inner node writes its second child, pushed or not.
        let mut stack = [const { MaybeUninit::<(Interval, u32)>::uninit() }; 257];
        let mut sp = 0;
        let (mut node, mut iv) = (0u32, Interval { tmin: zero, tmax: tmax0 });
        let mut act = live(&iv, best_t);
        loop {
            let nd = &fs.nodes[node as usize];
            if act != 0 && nd.kind < LEAF {
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
                let (lm, rm) = (live(&left, best_t), live(&right, best_t));
                let right_first = 2 * (neg[a] & act).count_ones() > act.count_ones();
                let (left, right) = ((nd.link, left, lm), (nd.link + 1, right, rm));
                let (first, second) = if right_first { (right, left) } else { (left, right) };
                // Without branches: the second child is written always and kept when both
                // are taken; a node with no lanes left pops at the top of the loop.
                let take_first = first.2 != 0;
                stack[sp].write((second.1, second.0));
                sp += (take_first && second.2 != 0) as usize;
                let k = if take_first { Mask::MAX } else { 0 };
                (node, act) = if take_first { (first.0, first.2) } else { (second.0, second.2) };
                iv = Interval {
                    tmin: blend(k, second.1.tmin, first.1.tmin),
                    tmax: blend(k, second.1.tmax, first.1.tmax),
                };
                continue;
            } else if act != 0 {
                let lo = max(lower_t(iv.tmin), one);
                for ft in &fs.tris[nd.link as usize..(nd.link + nd.kind - LEAF) as usize] {
                    let tri = &ft.tri;
                    let [or, op, oq, wr, wp, wq] = rows[tri.r as usize & 3];
                    let (np, nq) = (splat32(tri.np), splat32(tri.nq));
                    let den = sra(add(wr, sra(add(add(mul32(wp, np), mul32(wq, nq)), half), g.f)), g.t);
                    let num = sra(sub(sll(sub(splat(tri.d), or), g.f), add(mul32(op, np), mul32(oq, nq))), g.t);
                    let signs = act & ge(xor(num, den), zero);
                    if signs == 0 {
                        continue;
                    }
                    // floor(a / b) as in `div_floor`. A lane with b = 0 or a / b ≥ 2^32 − 2
                    // gets a t far outside [lo, hi] and fails the window, as the divider must.
                    let (a_, b_) = (abs(num), abs(den));
                    let q = div_f64(a_, b_);
                    let r = sub(a_, mul_lo32(q, b_));
                    let t = add(add(q, sign(r)), blend(ge(r, b_), zero, one));
                    let ok = signs & ge(t, lo) & le(t, min(best_t, t_top));
                    if ok == 0 {
                        continue;
                    }
                    let k = |o: W, p: i64, w: W| add(sub(o, splat(p)), sra(add(mul32(t, w), half), g.f));
                    let (kp, kq) = (k(op, tri.pp, wp), k(oq, tri.pq, wq));
                    let u = sub(mul32(splat32(tri.e1p), kq), mul32(splat32(tri.e1q), kp));
                    let v = sub(mul32(splat32(tri.e2q), kp), mul32(splat32(tri.e2p), kq));
                    let inside = ge(bit_or(u, v), zero) & le_unsigned(add(u, v), uv_max);
                    // t ≤ best t here, so (t, id) < best ⟺ t < best t or id < best id.
                    let id = splat(ft.id as i64);
                    let better = ok & inside & (lt(t, best_t) | lt(id, best_id));
                    best_t = blend(better, best_t, t);
                    best_id = blend(better, best_id, id);
                    best_u = blend(better, best_u, u);
                    best_v = blend(better, best_v, v);
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            // SAFETY: entries below the stack pointer were written by a push.
            (iv, node) = unsafe { stack[sp].assume_init() };
            act = live(&iv, best_t);
        }
        let (t, id, u, v) = (to_a(best_t), to_a(best_id), to_a(best_u), to_a(best_v));
        let shr = |x: i64| x.checked_shr(g.e).unwrap_or(0);
        std::array::from_fn(|l| {
            (id[l] != i64::MAX).then(|| Hit { tri: id[l] as u32, t: t[l], u: shr(u[l]), v: shr(v[l]) })
        })
    }
}

#[cfg(not(target_arch = "x86_64"))]
mod fallback {
    use crate::model::golden::{Golden, GridRay, Hit};
    use crate::render::fast::FastScene;
    pub const LANES: usize = 16;
    pub fn available(_: &crate::params::Params) -> bool {
        false
    }
    pub fn trace(_: &Golden, _: &FastScene, _: &[GridRay]) -> [Option<Hit>; LANES] {
        unreachable!("packets need AVX-512")
    }
}
