//! Hanika's accelerated Badouel/Wald triangle (seed 001 §2.1, eq. 2.1/2.2) in fixed point,
//! computed exactly from integer grid vertices. Bit widths are in docs/ARITHMETIC.md.

use serde::Serialize;

/// A triangle as the hardware stores it. Values are kept in i64 but each fits its ROM field:
/// r 2 bits; pp, pq n-bit unsigned; d (n+3)-bit signed grid units; np, nq m-bit signed with
/// F = m−1 fraction bits; e1p … e2q m-bit signed with E+F fraction bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct AccelTri {
    pub r: u8,
    pub pp: i64,
    pub pq: i64,
    pub d: i64,
    pub np: i64,
    pub nq: i64,
    pub e1p: i64,
    pub e1q: i64,
    pub e2p: i64,
    pub e2q: i64,
}

/// Integer vertex on the n-bit grid.
pub type GridVertex = [i64; 3];

/// Rounds a / b to the nearest integer, halves away from zero (so mirrored triangles get
/// mirrored values). `b` must not be zero.
pub fn div_round(a: i128, b: i128) -> i128 {
    let (a, b) = if b < 0 { (-a, -b) } else { (a, b) };
    let q = (2 * a.abs() + b) / (2 * b);
    if a < 0 { -q } else { q }
}

/// The exact integer normal n = (x1 − x0) × (x2 − x0).
pub fn cross(v: &[GridVertex; 3]) -> [i128; 3] {
    let b: [i128; 3] = std::array::from_fn(|k| (v[1][k] - v[0][k]) as i128);
    let c: [i128; 3] = std::array::from_fn(|k| (v[2][k] - v[0][k]) as i128);
    [b[1] * c[2] - b[2] * c[1], b[2] * c[0] - b[0] * c[2], b[0] * c[1] - b[1] * c[0]]
}

/// The projection axis r (smallest index of the largest |n_k|) and p, q.
pub fn axes(n: &[i128; 3]) -> (usize, usize, usize) {
    let mut r = 0;
    for k in 1..3 {
        if n[k].abs() > n[r].abs() {
            r = k;
        }
    }
    (r, (r + 1) % 3, (r + 2) % 3)
}

/// The largest edge ratio |x_ik − x_0k| / |n_r| of a triangle, as (numerator, denominator).
pub fn max_edge_ratio(v: &[GridVertex; 3]) -> Option<(i128, i128)> {
    let n = cross(v);
    let (r, p, q) = axes(&n);
    if n[r] == 0 {
        return None;
    }
    let a = [p, q].iter().flat_map(|&k| [1, 2].map(|i| (v[i][k] - v[0][k]).abs() as i128)).max().unwrap_or(0);
    Some((a, n[r].abs()))
}

/// Outcome of quantising one triangle.
pub struct Quantized {
    pub tri: AccelTri,
    /// At least one edge component was clamped to (−2^−E, 2^−E).
    pub clamped: bool,
}

/// Builds the accelerated triangle, or None when it is degenerate (n_r = 0).
/// `f` is the number of fraction bits (m − 1), `e` the edge shift.
pub fn quantize(v: &[GridVertex; 3], f: u32, e: u32) -> Option<Quantized> {
    let n = cross(v);
    let (r, p, q) = axes(&n);
    let nr = n[r];
    if nr == 0 {
        return None;
    }
    let one = 1i128 << f;
    let lim = one - 1; // symmetric m-bit range; +1.0 itself is not representable
    let np = div_round(n[p] << f, nr).clamp(-lim, lim);
    let nq = div_round(n[q] << f, nr).clamp(-lim, lim);
    let x0 = v[0].map(|x| x as i128);
    // d uses the quantised np, nq so the plane passes through x0 as the hardware sees it.
    let d = div_round((x0[r] << f) + x0[p] * np + x0[q] * nq, one);
    let mut clamped = false;
    let mut edge = |i: usize, k: usize| {
        let raw = div_round(((v[i][k] - v[0][k]) as i128) << (e + f), nr);
        if raw.abs() > lim {
            clamped = true;
        }
        raw.clamp(-lim, lim) as i64
    };
    let (e1p, e1q, e2p, e2q) = (edge(1, p), edge(1, q), edge(2, p), edge(2, q));
    Some(Quantized {
        tri: AccelTri {
            r: r as u8,
            pp: v[0][p],
            pq: v[0][q],
            d: d as i64,
            np: np as i64,
            nq: nq as i64,
            e1p,
            e1q,
            e2p,
            e2q,
        },
        clamped,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn div_round_is_symmetric() {
        assert_eq!(div_round(5, 2), 3);
        assert_eq!(div_round(-5, 2), -3);
        assert_eq!(div_round(5, -2), -3);
        assert_eq!(div_round(4, 3), 1);
        assert_eq!(div_round(-4, 3), -1);
    }

    #[test]
    fn axis_aligned_triangle() {
        // In the plane y = 7: n points along y, so r = 1, p = 2 (z), q = 0 (x).
        let v = [[0, 7, 0], [0, 7, 100], [100, 7, 0]];
        let t = quantize(&v, 31, 0).unwrap().tri;
        assert_eq!(t.r, 1);
        assert_eq!((t.np, t.nq, t.d), (0, 0, 7));
        assert_eq!((t.pp, t.pq), (0, 0));
        // e1p = (z1 − z0)/n_r with n_r = ±10000, scaled by 2^31.
        assert_eq!(t.e1p.abs(), div_round(100i128 << 31, 10000) as i64);
    }

    #[test]
    fn degenerate_is_none() {
        assert!(quantize(&[[1, 2, 3], [2, 4, 6], [3, 6, 9]], 31, 10).is_none());
        assert!(quantize(&[[1, 2, 3], [1, 2, 3], [5, 6, 9]], 31, 10).is_none());
    }

    #[test]
    fn clamping_is_reported() {
        // A sliver with n_r = 1 and an edge of 1000: e = 1000 > 2^−0.
        let v = [[0, 0, 0], [1000, 1, 0], [1, 0, 0]];
        assert!(quantize(&v, 31, 0).unwrap().clamped);
        assert!(!quantize(&[[0, 0, 0], [10, 0, 0], [0, 10, 0]], 31, 0).unwrap().clamped);
    }
}
