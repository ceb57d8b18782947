//! The on-chip pinhole ray generator (the thesis's demo): pixel after pixel, the ray of
//! `model::raygen::RayGen` — origin the eye's grid point, direction d0 + px·dx + py·dy — with
//! its three reciprocals from three sequential dividers (one quotient bit per clock, F + C + 1
//! clocks). While the traversal works on one ray, the next one is being divided.
//!
//! States: `div` (the reciprocals of the current pixel), `full` (`ray_valid` until the core
//! takes the ray; then the next pixel), `done` (after the last pixel).

use crate::model::raygen::RayGen;
use crate::rtl::{Module, Ty, UnOp};

const DIV: i128 = 0;
const FULL: i128 = 1;
const DONE: i128 = 2;

/// Ports: `ready` in; `ray_valid`, `ray_id`, `ox oy oz`, `wx wy wz`, `invx invy invz` out (the
/// core's ray inputs, in `top::core_inputs` order).
pub fn raygen_core(g: &RayGen, n: u32, m_bits: u32, c: u32, id_width: u32) -> Module {
    let mut m = Module::new("fxrt_raygen");
    let f = m_bits - 1;
    let qbits = f + c + 1;
    let ready = m.input("ready", Ty::BIT);
    let state = m.reg("state", Ty::u(2), Some(DIV));
    let in_div = m.eq_k("in_div", state, DIV);
    let in_full = m.eq_k("in_full", state, FULL);
    let take = m.and("take", in_full, ready);

    // Pixel counters and the direction, stepped when a ray is taken.
    let xw = crate::scene::rom::value_bits(g.width as usize);
    let yw = crate::scene::rom::value_bits(g.height as usize);
    let px = m.reg("px", Ty::u(xw), Some(0));
    let py = m.reg("py", Ty::u(yw), Some(0));
    let id = m.reg("pixel", Ty::u(id_width), Some(0));
    let last_x = m.eq_k("last_x", px, g.width as i128 - 1);
    let last_y = m.eq_k("last_y", py, g.height as i128 - 1);
    let last = m.and("last_pixel", last_x, last_y);
    let one_x = m.konst("one_x", px.ty, 1);
    let one_y = m.konst("one_y", py.ty, 1);
    let one_id = m.konst("one_id", id.ty, 1);
    let zero_x = m.konst("zero_x", px.ty, 0);
    let px_inc = m.add("px_inc", px, one_x);
    let py_inc = m.add("py_inc", py, one_y);
    let id_inc = m.add("pixel_inc", id, one_id);
    let px_next = m.mux("px_next", last_x, zero_x, px_inc);
    m.connect(px, px_next, Some(take));
    let row_end = m.and("row_end", take, last_x);
    m.connect(py, py_inc, Some(row_end));
    m.connect(id, id_inc, Some(take));
    // Directions in m + 2 bits, so no step in or just past the frame wraps.
    let dw = Ty::s(m_bits + 2);
    let mut w_out = Vec::new();
    for k in 0..3 {
        let a = ["x", "y", "z"][k];
        let dx = m.konst(&format!("dx_{a}"), dw, g.dx[k] as i128);
        let dy = m.konst(&format!("dy_{a}"), dw, g.dy[k] as i128);
        let row = m.reg(&format!("row_{a}"), dw, Some(g.d0[k] as i128));
        let d = m.reg(&format!("d_{a}"), dw, Some(g.d0[k] as i128));
        let row_next = m.add(&format!("row_next_{a}"), row, dy);
        m.connect(row, row_next, Some(row_end));
        let d_step = m.add(&format!("d_step_{a}"), d, dx);
        let d_next = m.mux(&format!("d_next_{a}"), last_x, row_next, d_step);
        m.connect(d, d_next, Some(take));
        w_out.push(m.resize(&format!("w_{a}"), d, m_bits));
    }

    // Three restoring dividers: q = floor(2^(F+C) / |w|), |w| = 1 for w = 0.
    let count = m.reg("div_count", Ty::u(crate::scene::rom::value_bits(qbits as usize)), Some(0));
    let one_c = m.konst("count_one", count.ty, 1);
    let count_inc = m.add("count_inc", count, one_c);
    let zero_c = m.konst("count_zero", count.ty, 0);
    let div_last = m.eq_k("div_last", count, qbits as i128 - 1);
    let count_next = m.mux("count_next", in_div, count_inc, zero_c);
    m.connect(count, count_next, None);
    let first_bit = m.eq_k("first_bit", count, 0);
    let lim = (1i128 << (m_bits + c - 1)) - 1;
    let mut inv_out = Vec::new();
    for (k, w) in w_out.iter().enumerate() {
        let a = ["x", "y", "z"][k];
        let zero_w = m.konst(&format!("zero_w_{a}"), w.ty, 0);
        let neg = m.lt(&format!("neg_{a}"), *w, zero_w);
        let is_zero = m.equals(&format!("w0_{a}"), *w, zero_w);
        let minus = m.un(&format!("minus_{a}"), UnOp::Neg, *w);
        let mag_s = m.mux(&format!("mag_s_{a}"), neg, minus, *w);
        let mag = m.un(&format!("mag_{a}"), UnOp::AsUnsigned, mag_s);
        let mag = m.resize(&format!("mag_w_{a}"), mag, f + 2);
        let one_m = m.konst(&format!("one_m_{a}"), mag.ty, 1);
        let b = m.mux(&format!("b_{a}"), is_zero, one_m, mag);
        let r = m.reg(&format!("rem_{a}"), Ty::u(f + 2), Some(0));
        let q = m.reg(&format!("quot_{a}"), Ty::u(qbits), Some(0));
        // Shift in the numerator's only 1 (its top bit) first, zeros after.
        let zero_r = m.konst(&format!("zero_r_{a}"), r.ty, 0);
        let r_in = m.mux(&format!("r_in_{a}"), first_bit, zero_r, r);
        let r2 = m.shl(&format!("r2_{a}"), r_in, 1);
        let bit = m.resize(&format!("bit_{a}"), first_bit, f + 2);
        let r3 = m.add(&format!("r3_{a}"), r2, bit);
        let ge = m.le(&format!("ge_{a}"), b, r3);
        let diff = m.sub(&format!("diff_{a}"), r3, b);
        let r_next = m.mux(&format!("r_next_{a}"), ge, diff, r3);
        m.connect(r, r_next, Some(in_div));
        let zero_q = m.konst(&format!("zero_q_{a}"), q.ty, 0);
        let q_in = m.mux(&format!("q_in_{a}"), first_bit, zero_q, q);
        let q2 = m.shl(&format!("q2_{a}"), q_in, 1);
        let ge_w = m.resize(&format!("ge_w_{a}"), ge, qbits);
        let q_next = m.add(&format!("q_next_{a}"), q2, ge_w);
        m.connect(q, q_next, Some(in_div));
        // Saturate to the m + C-bit range, then the sign.
        let lim_q = m.konst(&format!("lim_{a}"), q.ty, lim);
        let over = m.lt(&format!("over_{a}"), lim_q, q);
        let q_sat = m.mux(&format!("q_sat_{a}"), over, lim_q, q);
        let q_s = m.resize(&format!("q_s_{a}"), q_sat, m_bits + c);
        let q_s = m.un(&format!("q_signed_{a}"), UnOp::AsSigned, q_s);
        let q_neg = m.un(&format!("q_neg_{a}"), UnOp::Neg, q_s);
        inv_out.push(m.mux(&format!("inv_{a}"), neg, q_neg, q_s));
    }

    let k = |m: &mut Module, name: &str, v: i128| m.konst(name, Ty::u(2), v);
    let (s_div, s_full, s_done) = (k(&mut m, "st_div", DIV), k(&mut m, "st_full", FULL), k(&mut m, "st_done", DONE));
    let from_div = m.mux("from_div", div_last, s_full, s_div);
    let after = m.mux("after_take", last, s_done, s_div);
    let from_full = m.mux("from_full", ready, after, s_full);
    let state_next = m.case("state_next", state, &[(DIV as u128, from_div), (FULL as u128, from_full)], s_done);
    m.connect(state, state_next, None);

    m.output("ray_valid", in_full);
    m.output("ray_id", id);
    for (k, name) in ["ox", "oy", "oz"].iter().enumerate() {
        let o = m.konst(&format!("eye_{name}"), Ty::u(n), g.eye[k] as i128);
        m.output(name, o);
    }
    for (name, w) in ["wx", "wy", "wz"].iter().zip(&w_out) {
        m.output(name, *w);
    }
    for (name, inv) in ["invx", "invy", "invz"].iter().zip(&inv_out) {
        m.output(name, *inv);
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cores::top::{CoreParams, core_with_raygen};
    use crate::flow::frame::{PixelRay, collect_batched, mismatches};
    use crate::model::golden::Golden;
    use crate::params::Params;
    use crate::render::camera::Camera;
    use crate::rtl::sim::Sim;
    use crate::scene::images::SceneRoms;
    use crate::scene::{Scene, SceneSource};

    /// A camera inside the Cornell box, looking at the back wall.
    fn inside() -> (Scene, Camera) {
        let scene = Scene::load(&SceneSource::Builtin("cornell".into()), &Params::default()).unwrap();
        let mut cam = Camera::default_for(&scene, 12, 10);
        cam.eye = [278.0, 273.0, 60.0];
        cam.at = [300.0, 250.0, 559.0];
        (scene, cam)
    }

    #[test]
    fn emits_the_golden_rays_in_pixel_order() {
        let (scene, cam) = inside();
        let g = Golden::new(&scene);
        let rg = RayGen::new(&scene, &cam).unwrap();
        let p = &scene.params;
        let m = raygen_core(&rg, p.n, p.m, p.c, 8);
        let mut sim = Sim::new(&m);
        let out = |name: &str| m.handle(m.outputs.iter().find(|o| o.0 == name).unwrap().1);
        let ready = m.handle(m.inputs[0]);
        let mut seen = 0u32;
        for cycle in 0..20_000 {
            // The consumer is ready only now and then.
            sim.set(ready, (cycle % 3 == 0) as i128);
            sim.eval();
            if sim.get(out("ray_valid")) == 1 && cycle % 3 == 0 {
                let (px, py) = (seen % cam.width, seen / cam.width);
                let want = rg.ray(&g, px, py);
                assert_eq!(sim.get(out("ray_id")), seen as i128);
                for (k, a) in ["x", "y", "z"].iter().enumerate() {
                    assert_eq!(sim.get(out(&format!("o{a}"))), want.o[k] as i128);
                    assert_eq!(sim.get(out(&format!("w{a}"))), want.w[k] as i128, "pixel {px},{py}");
                    assert_eq!(sim.get(out(&format!("inv{a}"))), want.inv[k], "pixel {px},{py}");
                }
                seen += 1;
            }
            sim.tick();
        }
        assert_eq!(seen, cam.width * cam.height);
    }

    #[test]
    fn the_core_with_its_generator_renders_the_golden_frame() {
        let (scene, cam) = inside();
        let g = Golden::new(&scene);
        let rg = RayGen::new(&scene, &cam).unwrap();
        let roms = SceneRoms::of(&scene);
        let p = CoreParams::new(&roms, 8, 1);
        let rays: Vec<PixelRay> = (0..cam.width * cam.height)
            .map(|i| PixelRay { pixel: i, ray: rg.ray(&g, i % cam.width, i / cam.width) })
            .collect();
        let (results, stats) = collect_batched(&core_with_raygen(&p, &roms, &rg), rays.len(), 0, &|_| {});
        assert_eq!(mismatches(&scene, &rays, &results), 0);
        assert!(results.iter().all(|r| r.1.is_some()), "every ray from inside the box hits a wall");
        assert!(stats.busy_cycles > 0);
    }

    #[test]
    fn a_camera_outside_the_box_is_refused() {
        let scene = Scene::load(&SceneSource::Builtin("cornell".into()), &Params::default()).unwrap();
        let cam = Camera::default_for(&scene, 8, 8);
        assert_eq!(RayGen::new(&scene, &cam).unwrap_err().0, "eye");
    }
}
