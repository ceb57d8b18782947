//! The ray/triangle intersection pipeline (seed 001 §3.3, figure 3.4): one (ray, triangle)
//! pair per clock with a valid bit and a tag, and after a fixed latency the tag, hit, t, u, v,
//! bit-identical to `Golden::intersect` for the same quantised inputs (docs/ARITHMETIC.md §4).
//! When there is no hit, t, u and v read 0.

use super::divider::{self, divider_core};
use crate::rtl::{BinOp, Module, Sig, Ty, UnOp};
use serde::Serialize;
use std::rc::Rc;

/// The widths of one parameter set.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct IntersectParams {
    pub n: u32,
    pub m: u32,
    pub t: u32,
    pub e: u32,
    /// Width of the pass-through tag (ray id and triangle number, packed by the user).
    pub tag_width: u32,
    /// Quotient bits per divider stage: 1, or 2 for half the divider latency.
    pub div_bits: u32,
}

impl IntersectParams {
    pub fn f(&self) -> u32 {
        self.m - 1
    }
    /// Numerator: |num| < 2^(n+F+2) (ARITHMETIC.md §4).
    pub fn num_width(&self) -> u32 {
        self.n + self.f() + 3
    }
    pub fn den_width(&self) -> u32 {
        self.m + 2
    }
    pub fn name(&self) -> String {
        let r4 = if self.div_bits == 2 { "_r4" } else { "" };
        format!("fxrt_intersect_n{}_m{}_t{}_e{}_tag{}{r4}", self.n, self.m, self.t, self.e, self.tag_width)
    }
    /// Rejects widths the RTL layer cannot hold (signals are at most 128 bits), naming the
    /// parameter to change.
    pub fn check(&self) -> crate::error::Result<()> {
        use crate::error::Error;
        let max = crate::rtl::width::MAX_WIDTH;
        let f = self.f();
        for (what, bits, param) in [
            ("the numerator (n + m + 2)", self.num_width(), "m"),
            ("ω·np (2m + 1)", 2 * self.m + 1, "m"),
            ("the barycentric sums (n + m + 4)", self.n + self.m + 4, "n"),
            ("the u + v limit (E + m + 1)", self.e + f + 2, "edge-shift"),
        ] {
            if bits > max {
                return Err(Error::param(
                    param,
                    format!("{what} needs {bits} bits; the RTL layer holds at most {max}"),
                ));
            }
        }
        if !(1..=2).contains(&self.div_bits) {
            return Err(Error::param("div-bits", format!("{} is out of range: must be 1 or 2", self.div_bits)));
        }
        if self.tag_width == 0 || self.tag_width > 64 {
            return Err(Error::param("tag-width", format!("{} is out of range: must be 1..=64", self.tag_width)));
        }
        Ok(())
    }

    /// The divider this pipeline instantiates (operands shortened by T).
    pub fn divider(&self) -> Module {
        divider_core(self.n, self.div_bits, self.num_width() - self.t, self.den_width() - self.t)
    }

    /// Input register, products, numerator/denominator, divider, t·ω, k, e·k, u/v and test.
    pub fn latency(&self) -> u32 {
        3 + divider::latency(self.n, self.div_bits) + 4
    }
}

/// Input port names in order, with their types.
pub fn input_ports(p: &IntersectParams) -> Vec<(&'static str, Ty)> {
    let (n, m) = (p.n, p.m);
    vec![
        ("valid", Ty::BIT),
        ("tag", Ty::u(p.tag_width)),
        ("ox", Ty::u(n)),
        ("oy", Ty::u(n)),
        ("oz", Ty::u(n)),
        ("wx", Ty::s(m)),
        ("wy", Ty::s(m)),
        ("wz", Ty::s(m)),
        ("r", Ty::u(2)),
        ("pp", Ty::u(n)),
        ("pq", Ty::u(n)),
        ("d", Ty::s(n + 3)),
        ("np", Ty::s(m)),
        ("nq", Ty::s(m)),
        ("e1p", Ty::s(m)),
        ("e1q", Ty::s(m)),
        ("e2p", Ty::s(m)),
        ("e2q", Ty::s(m)),
    ]
}

/// v[sel] for a 2-bit axis number (3 picks v[0]; it never occurs).
pub(crate) fn pick(m: &mut Module, name: &str, sel: Sig, v: [Sig; 3]) -> Sig {
    m.case(name, sel, &[(1, v[1]), (2, v[2])], v[0])
}

/// A pipeline register for each signal, named after it with the stage's prefix (a previous
/// stage's prefix, such as `s3_` or `dv12_`, is replaced, not stacked).
fn stage(m: &mut Module, prefix: &str, sigs: &[Sig]) -> Vec<Sig> {
    sigs.iter()
        .map(|s| {
            let old = &m.sig(s.id).name;
            let base = match old.split_once('_') {
                Some((p, rest))
                    if p.trim_end_matches(|c: char| c.is_ascii_digit()).len() < p.len()
                        && p.starts_with(|c: char| c.is_ascii_alphabetic()) =>
                {
                    rest
                }
                _ => old.as_str(),
            };
            let name = format!("{prefix}_{base}");
            m.delay(&name, *s)
        })
        .collect()
}

/// (a + 1) mod 3 for a 2-bit axis number.
fn next_axis(m: &mut Module, name: &str, a: Sig) -> Sig {
    let zero = m.konst(&format!("{name}_zero"), Ty::u(2), 0);
    let one = m.konst(&format!("{name}_one"), Ty::u(2), 1);
    let two = m.konst(&format!("{name}_two"), Ty::u(2), 2);
    let wraps = m.bin(&format!("{name}_wraps"), BinOp::Eq, a, two);
    let inc = m.add(&format!("{name}_inc"), a, one);
    m.mux(name, wraps, zero, inc)
}

/// round(x / 2^s): (x + 2^(s−1)) >> s, at x's width.
fn shr_round(m: &mut Module, name: &str, x: Sig, s: u32) -> Sig {
    if s == 0 {
        return x;
    }
    let half = m.konst(&format!("{name}_half"), x.ty, 1i128 << (s - 1));
    let y = m.add(&format!("{name}_biased"), x, half);
    m.shr(name, y, s)
}

pub(crate) fn as_signed_wider(m: &mut Module, name: &str, x: Sig) -> Sig {
    let w = m.resize(&format!("{name}_w"), x, x.ty.width + 1);
    m.un(name, UnOp::AsSigned, w)
}

pub fn intersect_core(p: &IntersectParams) -> Module {
    let (n, mm, f) = (p.n, p.m, p.f());
    let mut m = Module::new(&p.name());
    let ins: Vec<Sig> = input_ports(p).iter().map(|(name, ty)| m.input(name, *ty)).collect();
    // Stage 1: register the inputs.
    let r = stage(&mut m, "s1", &ins);
    let [valid, tag, ox, oy, oz, wx, wy, wz, rr, pp, pq, d, np, nq, e1p, e1q, e2p, e2q] = r[..] else { unreachable!() };
    // Permute by r: (r, p, q) = (r, r+1 mod 3, r+2 mod 3).
    let (o, w) = ([ox, oy, oz], [wx, wy, wz]);
    let sel_p = next_axis(&mut m, "perm_p", rr);
    let sel_q = next_axis(&mut m, "perm_q", sel_p);
    let o_r = pick(&mut m, "o_r", rr, o);
    let o_p = pick(&mut m, "o_p", sel_p, o);
    let o_q = pick(&mut m, "o_q", sel_q, o);
    let w_r = pick(&mut m, "w_r", rr, w);
    let w_p = pick(&mut m, "w_p", sel_p, w);
    let w_q = pick(&mut m, "w_q", sel_q, w);
    // Origin components as signed n+1 bits, so they multiply with signed normals.
    let o_p_s = as_signed_wider(&mut m, "o_p_s", o_p);
    let o_q_s = as_signed_wider(&mut m, "o_q_s", o_q);
    let o_r_s = as_signed_wider(&mut m, "o_r_s", o_r);
    let pp_s = as_signed_wider(&mut m, "pp_s", pp);
    let pq_s = as_signed_wider(&mut m, "pq_s", pq);
    // Stage 2: the four products, d − O_r, and the k bases O_p − pp, O_q − pq.
    let onp = m.mul("o_p_np", o_p_s, np);
    let onq = m.mul("o_q_nq", o_q_s, nq);
    let wnp = m.mul("w_p_np", w_p, np);
    let wnq = m.mul("w_q_nq", w_q, nq);
    let d_w = m.resize("d_w", d, n + 4);
    let o_r_w = m.resize("o_r_w", o_r_s, n + 4);
    let dmo = m.sub("d_minus_or", d_w, o_r_w);
    let kp0 = m.sub("kp_base", o_p_s, pp_s);
    let kq0 = m.sub("kq_base", o_q_s, pq_s);
    let s2: Vec<Sig> =
        stage(&mut m, "s2", &[onp, onq, wnp, wnq, dmo, w_r, valid, tag, kp0, kq0, w_p, w_q, e1p, e1q, e2p, e2q]);
    let [onp, onq, wnp, wnq, dmo, w_r, valid, tag, kp0, kq0, w_p, w_q, e1p, e1q, e2p, e2q] = s2[..] else {
        unreachable!()
    };
    // Stage 3: num = ((d − O_r) << F) − O_p·np − O_q·nq, den = ω_r + rnd(ω_p·np + ω_q·nq, F).
    let wn = p.num_width();
    let dmo_w = m.resize("num_dmo", dmo, wn);
    let dmo_sh = m.shl("num_dmo_shifted", dmo_w, f);
    let onp_w = m.resize("num_onp", onp, wn);
    let onq_w = m.resize("num_onq", onq, wn);
    let num_a = m.sub("num_a", dmo_sh, onp_w);
    let num = m.sub("num", num_a, onq_w);
    let wsum_w = 2 * mm + 1;
    let wnp_w = m.resize("den_wnp", wnp, wsum_w);
    let wnq_w = m.resize("den_wnq", wnq, wsum_w);
    let wsum = m.add("den_sum", wnp_w, wnq_w);
    let wsum_r = shr_round(&mut m, "den_sum_rounded", wsum, f);
    let wd = p.den_width();
    let wsum_n = m.resize("den_sum_narrow", wsum_r, wd);
    let w_r_w = m.resize("den_wr", w_r, wd);
    let den = m.add("den", w_r_w, wsum_n);
    // Division precision T: drop the T low bits of both (wiring only).
    let num_t = m.shr("num_t", num, p.t);
    let num_t = m.resize("num_short", num_t, wn - p.t);
    let den_t = m.shr("den_t", den, p.t);
    let den_t = m.resize("den_short", den_t, wd - p.t);
    let num_r = m.delay("s3_num", num_t);
    let den_r = m.delay("s3_den", den_t);
    let side: Vec<Sig> = stage(&mut m, "s3", &[valid, tag, kp0, kq0, w_p, w_q, e1p, e1q, e2p, e2q]);
    // The divider, with everything else riding along.
    let div = Rc::new(p.divider());
    let [dv_t, dv_ok] = m.instance("u_div", &div, &[num_r, den_r])[..] else { unreachable!() };
    let mut side = side;
    for k in 1..=divider::latency(n, p.div_bits) {
        side = stage(&mut m, &format!("dv{k}"), &side);
    }
    let [valid, tag, kp0, kq0, w_p, w_q, e1p, e1q, e2p, e2q] = side[..] else { unreachable!() };
    // Stage D+1: t·ω_p, t·ω_q (t as signed n+2 bits).
    let t_s = as_signed_wider(&mut m, "t_s", dv_t);
    let tp = m.mul("t_wp", t_s, w_p);
    let tq = m.mul("t_wq", t_s, w_q);
    let x1: Vec<Sig> = stage(&mut m, "x1", &[tp, tq, dv_t, dv_ok, valid, tag, kp0, kq0, e1p, e1q, e2p, e2q]);
    let [tp, tq, t, ok, valid, tag, kp0, kq0, e1p, e1q, e2p, e2q] = x1[..] else { unreachable!() };
    // Stage D+2: kp = (O_p − pp) + rnd(t·ω_p, F), kq likewise (n+3 bits).
    let tp_r = shr_round(&mut m, "tp_rounded", tp, f);
    let tq_r = shr_round(&mut m, "tq_rounded", tq, f);
    let kw = n + 3;
    let tp_n = m.resize("tp_narrow", tp_r, kw);
    let tq_n = m.resize("tq_narrow", tq_r, kw);
    let kp0_w = m.resize("kp_base_w", kp0, kw);
    let kq0_w = m.resize("kq_base_w", kq0, kw);
    let kp = m.add("kp", kp0_w, tp_n);
    let kq = m.add("kq", kq0_w, tq_n);
    let x2: Vec<Sig> = stage(&mut m, "x2", &[kp, kq, t, ok, valid, tag, e1p, e1q, e2p, e2q]);
    let [kp, kq, t, ok, valid, tag, e1p, e1q, e2p, e2q] = x2[..] else { unreachable!() };
    // Stage D+3: the four barycentric products.
    let a1 = m.mul("e1p_kq", e1p, kq);
    let a2 = m.mul("e1q_kp", e1q, kp);
    let b1 = m.mul("e2q_kp", e2q, kp);
    let b2 = m.mul("e2p_kq", e2p, kq);
    let x3: Vec<Sig> = stage(&mut m, "x3", &[a1, a2, b1, b2, t, ok, valid, tag]);
    let [a1, a2, b1, b2, t, ok, valid, tag] = x3[..] else { unreachable!() };
    // Stage D+4: u, v, the hit test, outputs zeroed on a miss.
    let uw = (mm + kw + 1).max(p.e + f + 2);
    let a1w = m.resize("u_a", a1, uw);
    let a2w = m.resize("u_b", a2, uw);
    let b1w = m.resize("v_a", b1, uw);
    let b2w = m.resize("v_b", b2, uw);
    let u = m.sub("u", a1w, a2w);
    let v = m.sub("v", b1w, b2w);
    let uv = m.add("u_plus_v", u, v);
    let zero = m.konst("uv_zero", Ty::s(uw), 0);
    let limit = m.konst("uv_limit", Ty::s(uw), 1i128 << (p.e + f));
    let u_neg = m.bin("u_neg", BinOp::Lt, u, zero);
    let v_neg = m.bin("v_neg", BinOp::Lt, v, zero);
    let over = m.bin("uv_over", BinOp::Lt, limit, uv);
    let bad1 = m.bin("bary_bad_a", BinOp::Or, u_neg, v_neg);
    let bad = m.bin("bary_bad", BinOp::Or, bad1, over);
    let one = m.konst("hit_one", Ty::BIT, 1);
    let inside = m.bin("bary_inside", BinOp::Xor, bad, one);
    let hit = m.bin("hit_c", BinOp::And, inside, ok);
    let u_out = scaled_out(&mut m, "u_out", u, p.e, mm);
    let v_out = scaled_out(&mut m, "v_out", v, p.e, mm);
    let t_zero = m.konst("t_zero", t.ty, 0);
    let uv_zero = m.konst("uvo_zero", Ty::u(mm), 0);
    let t_o = m.mux("t_c", hit, t, t_zero);
    let u_o = m.mux("u_c", hit, u_out, uv_zero);
    let v_o = m.mux("v_c", hit, v_out, uv_zero);
    for (name, s) in [("valid_out", valid), ("tag_out", tag), ("hit", hit), ("t", t_o), ("u", u_o), ("v", v_o)] {
        let r = m.delay(&format!("q_{name}"), s);
        m.output(name, r);
    }
    m
}

/// u >> E as m bits unsigned (a hit has u in [0, 2^(E+F)], so the result is in [0, 2^F]).
fn scaled_out(m: &mut Module, name: &str, u: Sig, e: u32, mm: u32) -> Sig {
    if e >= u.ty.width - 1 {
        return m.konst(name, Ty::u(mm), 0);
    }
    let sh = m.shr(&format!("{name}_shifted"), u, e);
    let low = m.resize(&format!("{name}_low"), sh, mm);
    m.un(name, UnOp::AsUnsigned, low)
}

/// The input vector of one (ray, triangle) pair, in `input_ports` order.
pub fn pack_inputs(tag: u64, tri: &crate::scene::accel::AccelTri, ray: &crate::model::golden::GridRay) -> Vec<i128> {
    let mut v = vec![1, tag as i128];
    v.extend(ray.o.iter().map(|&x| x as i128));
    v.extend(ray.w.iter().map(|&x| x as i128));
    v.extend([tri.r as i128, tri.pp as i128, tri.pq as i128, tri.d as i128, tri.np as i128, tri.nq as i128]);
    v.extend([tri.e1p as i128, tri.e1q as i128, tri.e2p as i128, tri.e2q as i128]);
    v
}

/// The outputs the pipeline must produce for a valid input: (valid, tag, hit, t, u, v).
pub fn expected_outputs(tag: u64, hit: Option<crate::model::golden::TriHit>) -> [i128; 6] {
    match hit {
        Some(h) => [1, tag as i128, 1, h.t as i128, h.u as i128, h.v as i128],
        None => [1, tag as i128, 0, 0, 0, 0],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::golden::Golden;
    use crate::params::Params;
    use crate::rtl::sim::Sim;
    use crate::scene::Scene;

    /// Random rays against random triangles of a built-in scene, through the Rust simulation
    /// of the pipeline, against the golden model.
    fn check(params: Params, div_bits: u32, count: usize) -> usize {
        let scene = Scene::load(&crate::scene::SceneSource::Builtin("random".into()), &params).unwrap();
        let g = Golden::new(&scene);
        let p = IntersectParams { n: params.n, m: params.m, t: params.t, e: scene.edge_shift, tag_width: 24, div_bits };
        let module = intersect_core(&p);
        let mut sim = Sim::new(&module);
        let ins: Vec<_> = module.inputs.iter().map(|&i| module.handle(i)).collect();
        let outs: Vec<_> = module.outputs.iter().map(|(_, i)| module.handle(*i)).collect();
        let lat = p.latency() as usize;
        let mut rng = 0x1234_5678_9abc_def1u64;
        let mut next = move || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            rng
        };
        let mut expected = Vec::new();
        let mut hits = 0;
        for i in 0..count + lat {
            if i < count {
                let ti = (next() % scene.tris.len() as u64) as usize;
                let tri = &scene.tris[ti];
                // Aim at a point of the triangle's plane in or near the triangle, so most
                // pairs hit and many graze an edge.
                let hi = scene.grid_box.hi;
                let o: [i64; 3] = std::array::from_fn(|k| (next() % (hi[k] as u64 + 1)) as i64);
                let v = scene.grid_tris[ti];
                let (b1, b2) = ((next() % 1201) as f64 / 1000.0 - 0.1, (next() % 1201) as f64 / 1000.0 - 0.1);
                let target: [f64; 3] = std::array::from_fn(|k| {
                    v[0][k] as f64 + b1 * (v[1][k] - v[0][k]) as f64 + b2 * (v[2][k] - v[0][k]) as f64
                });
                let dir: [f64; 3] = std::array::from_fn(|k| target[k] - o[k] as f64);
                let len = dir.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-9);
                let w = crate::model::ray::quantize_direction(dir.map(|x| x / len), g.f);
                let ray = g.ray(o, w);
                let h = g.intersect(tri, &ray);
                hits += h.is_some() as usize;
                expected.push(expected_outputs(i as u64, h));
                for (s, v) in ins.iter().zip(pack_inputs(i as u64, tri, &ray)) {
                    sim.set(*s, v);
                }
            } else {
                sim.set(ins[0], 0);
            }
            sim.tick();
            if i + 1 >= lat {
                let k = i + 1 - lat;
                if k < count {
                    let got: Vec<i128> = outs.iter().map(|o| sim.get(*o)).collect();
                    assert_eq!(got, expected[k].to_vec(), "vector {k} with {params:?}");
                }
            }
        }
        hits
    }

    #[test]
    fn pipeline_matches_golden_at_defaults_and_stress_widths() {
        for params in [
            Params::default(),
            Params { n: 16, m: 16, ..Params::default() },
            Params { n: 23, m: 27, t: 5, ..Params::default() },
            Params { n: 32, m: 40, ..Params::default() },
        ] {
            let hits = check(params, 1, 3000);
            assert_eq!(hits, check(params, 2, 3000));
            assert!(hits > 1000 && hits < 2900, "{hits} hits of 3000 with {params:?}: both outcomes must be exercised");
        }
    }

    #[test]
    fn latency_at_the_thesis_setting_is_within_41() {
        let p = IntersectParams { n: 29, m: 32, t: 0, e: 10, tag_width: 8, div_bits: 1 };
        assert!(p.latency() <= 41, "{}", p.latency());
    }
}
