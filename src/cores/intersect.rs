//! The ray/triangle intersection pipeline (seed 001 §3.3, figure 3.4): one (ray, triangle)
//! pair per clock with a valid bit and a tag, and after a fixed latency the tag, hit, t, u, v,
//! bit-identical to `Golden::intersect` for the same quantised inputs (docs/ARITHMETIC.md §4).
//! When there is no hit, t, u and v read 0.

use super::divider::{self, divider_core};
use crate::rtl::build::{Builder, S};
use crate::rtl::pipeline::{Pipeline, Policy};
use crate::rtl::{Module, Ty};
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

/// (a + 1) mod 3 for a 2-bit axis number.
fn next_axis(a: S<'_>) -> S<'_> {
    a.eq(2).select(a.k(0), a + 1)
}

/// round(x / 2^s): (x + 2^(s−1)) >> s, at x's width.
fn shr_round(x: S<'_>, s: u32) -> S<'_> {
    if s == 0 { x } else { (x + (1i128 << (s - 1))) >> s }
}

crate::bundle! {
    /// The ports, registered.
    struct Inputs { valid, tag, ox, oy, oz, wx, wy, wz, r, pp, pq, d, np, nq, e1p, e1q, e2p, e2q }
}
crate::bundle! {
    /// After the permutation by r: the products of the plane test and the k bases.
    struct Products { onp, onq, wnp, wnq, dmo, w_r, kp0, kq0 }
}
crate::bundle! {
    /// The divider's operands, T low bits dropped.
    struct Quotient { num, den }
}
crate::bundle! {
    /// t·ω_p and t·ω_q.
    struct Moved { tp, tq }
}
crate::bundle! {
    /// The hit point's coordinates relative to the triangle's first vertex.
    struct Point { kp, kq }
}
crate::bundle! {
    /// The four barycentric products.
    struct Bary { a1, a2, b1, b2 }
}
crate::bundle! {
    /// The result ports.
    struct Outcome { valid_out, tag_out, hit, t, u, v }
}

pub fn intersect_core(p: &IntersectParams) -> Module {
    let (m, latency) = intersect_core_with(p, Policy::default());
    assert_eq!(latency, p.latency(), "latency formula and stages disagree");
    m
}

/// The pipeline with the stages `policy` merges left unregistered (the same results, less
/// latency), and its latency counted from the stages.
pub fn intersect_core_with(p: &IntersectParams, policy: Policy) -> (Module, u32) {
    let (n, mm, f) = (p.n, p.m, p.f());
    // Merged stages make another module: its name says which.
    let merged: String = policy.merge.iter().map(|s| format!("_m{s}")).collect();
    let b = Builder::new(&format!("{}{merged}", p.name()));
    let ins: Vec<S> = input_ports(p).iter().map(|(name, ty)| b.input(name, *ty)).collect();
    let pipe = Pipeline::new(&b, policy);
    let [valid, tag, ox, oy, oz, wx, wy, wz, r, pp, pq, d, np, nq, e1p, e1q, e2p, e2q] = ins[..] else {
        unreachable!("input_ports has 18 ports")
    };
    let x = pipe.stage(
        "inputs",
        "register the inputs",
        Inputs { valid, tag, ox, oy, oz, wx, wy, wz, r, pp, pq, d, np, nq, e1p, e1q, e2p, e2q },
    );
    // Permute by r: (r, p, q) = (r, r+1 mod 3, r+2 mod 3).
    let sel_p = next_axis(x.r).name("perm_p");
    let sel_q = next_axis(sel_p).name("perm_q");
    let (o, w) = ([x.ox, x.oy, x.oz], [x.wx, x.wy, x.wz]);
    let o_r = b.pick(x.r, o).name("o_r");
    let o_p = b.pick(sel_p, o).name("o_p");
    let o_q = b.pick(sel_q, o).name("o_q");
    let w_r = b.pick(x.r, w).name("w_r");
    let w_p = b.pick(sel_p, w).name("w_p");
    let w_q = b.pick(sel_q, w).name("w_q");
    // Origin components as signed n+1 bits, so they multiply with signed normals.
    let (o_p_s, o_q_s) = (o_p.xsigned(), o_q.xsigned());
    let prod = pipe.stage(
        "products",
        "O_p·np, O_q·nq, ω_p·np, ω_q·nq; d − O_r; O_p − pp, O_q − pq",
        Products {
            onp: o_p_s.xmul(x.np),
            onq: o_q_s.xmul(x.nq),
            wnp: w_p.xmul(x.np),
            wnq: w_q.xmul(x.nq),
            dmo: x.d.resize(n + 4) - o_r.xsigned().resize(n + 4),
            w_r,
            kp0: o_p_s - x.pp.xsigned(),
            kq0: o_q_s - x.pq.xsigned(),
        },
    );
    // num = ((d − O_r) << F) − O_p·np − O_q·nq, den = ω_r + rnd(ω_p·np + ω_q·nq, F).
    let (wn, wd) = (p.num_width(), p.den_width());
    let num = ((prod.dmo.resize(wn) << f) - prod.onp.resize(wn) - prod.onq.resize(wn)).name("num");
    let wsum = prod.wnp.resize(2 * mm + 1) + prod.wnq.resize(2 * mm + 1);
    let den = (prod.w_r.resize(wd) + shr_round(wsum, f).resize(wd)).name("den");
    // Division precision T: drop the T low bits of both (wiring only).
    let q = pipe.stage(
        "quotient",
        "numerator and rounded denominator, T bits dropped",
        Quotient { num: (num >> p.t).resize(wn - p.t), den: (den >> p.t).resize(wd - p.t) },
    );
    let div = pipe.instance("u_div", &Rc::new(p.divider()), &[q.num, q.den], divider::latency(n, p.div_bits));
    let (t, ok) = (div.get("t"), div.get("ok"));
    // t·ω_p, t·ω_q (t as signed n+2 bits).
    let t_s = t.xsigned();
    let mv = pipe.stage("moved", "t·ω_p, t·ω_q", Moved { tp: t_s.xmul(pipe.now(w_p)), tq: t_s.xmul(pipe.now(w_q)) });
    // kp = (O_p − pp) + rnd(t·ω_p, F), kq likewise (n+3 bits).
    let kw = n + 3;
    let pt = pipe.stage(
        "point",
        "kp, kq: the hit point relative to the first vertex",
        Point {
            kp: pipe.now(prod.kp0).resize(kw) + shr_round(mv.tp, f).resize(kw),
            kq: pipe.now(prod.kq0).resize(kw) + shr_round(mv.tq, f).resize(kw),
        },
    );
    let bary = pipe.stage(
        "bary",
        "e1p·kq, e1q·kp, e2q·kp, e2p·kq",
        Bary {
            a1: pipe.now(x.e1p).xmul(pt.kq),
            a2: pipe.now(x.e1q).xmul(pt.kp),
            b1: pipe.now(x.e2q).xmul(pt.kp),
            b2: pipe.now(x.e2p).xmul(pt.kq),
        },
    );
    // u, v, the hit test, outputs zeroed on a miss.
    let uw = (mm + kw + 1).max(p.e + f + 2);
    let u = (bary.a1.resize(uw) - bary.a2.resize(uw)).name("u");
    let v = (bary.b1.resize(uw) - bary.b2.resize(uw)).name("v");
    let over = u.k(1i128 << (p.e + f)).lt(u + v);
    let inside = !(u.lt(0) | v.lt(0) | over);
    let hit = (inside & pipe.now(ok)).name("hit_c");
    let t_now = pipe.now(t);
    let res = pipe.stage(
        "result",
        "the barycentric test; t, u, v zeroed on a miss",
        Outcome {
            valid_out: pipe.now(x.valid),
            tag_out: pipe.now(x.tag),
            hit,
            t: hit.select(t_now, 0),
            u: hit.select(scaled_out(u, p.e, mm), 0),
            v: hit.select(scaled_out(v, p.e, mm), 0),
        },
    );
    let latency = pipe.finish();
    for (name, s) in [
        ("valid_out", res.valid_out),
        ("tag_out", res.tag_out),
        ("hit", res.hit),
        ("t", res.t),
        ("u", res.u),
        ("v", res.v),
    ] {
        b.output(name, s);
    }
    (b.finish(), latency)
}

/// u >> E as m bits unsigned (a hit has u in [0, 2^(E+F)], so the result is in [0, 2^F]).
fn scaled_out(u: S<'_>, e: u32, mm: u32) -> S<'_> {
    if e >= u.width() - 1 {
        return u.b.konst(Ty::u(mm), 0);
    }
    (u >> e).resize(mm).unsigned()
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
        check_with(params, div_bits, count, Policy::default())
    }

    fn check_with(params: Params, div_bits: u32, count: usize, policy: Policy) -> usize {
        let scene = Scene::load(&crate::scene::SceneSource::Builtin("random".into()), &params).unwrap();
        let g = Golden::new(&scene);
        let p = IntersectParams { n: params.n, m: params.m, t: params.t, e: scene.edge_shift, tag_width: 24, div_bits };
        let (module, lat) = intersect_core_with(&p, policy);
        let mut sim = Sim::new(&module);
        let ins: Vec<_> = module.inputs.iter().map(|&i| module.handle(i)).collect();
        let outs: Vec<_> = module.outputs.iter().map(|(_, i)| module.handle(*i)).collect();
        let lat = lat as usize;
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

    /// Register boundaries move by a parameter, not by editing the core: two stages merged,
    /// two cycles less latency, the same results.
    #[test]
    fn merged_stages_keep_every_result() {
        let merge = Policy { merge: vec!["moved".into(), "bary".into()] };
        let p = IntersectParams { n: 29, m: 32, t: 0, e: 18, tag_width: 24, div_bits: 1 };
        assert_eq!(intersect_core_with(&p, merge.clone()).1, p.latency() - 2);
        assert_eq!(check_with(Params::default(), 1, 2000, merge), check(Params::default(), 1, 2000));
    }

    #[test]
    fn latency_at_the_thesis_setting_is_within_41() {
        let p = IntersectParams { n: 29, m: 32, t: 0, e: 10, tag_width: 8, div_bits: 1 };
        assert!(p.latency() <= 41, "{}", p.latency());
    }
}
