//! The on-chip pinhole ray generator (the thesis's demo): pixel after pixel, the ray of
//! `model::raygen::RayGen` — origin the eye's grid point, direction d0 + px·dx + py·dy — with
//! its three reciprocals from three sequential dividers (a clock to load the divisors, then one
//! quotient bit per clock: F + C + 2 clocks, and one more to hand the ray over). While the
//! traversal works on one ray, the next one is being divided.
//!
//! States: `div` (the reciprocals of the current pixel), `full` (`ray_valid` until the core
//! takes the ray; then the next pixel), `done` (after the last pixel).

use crate::model::raygen::RayGen;
use crate::rtl::build::Builder;
use crate::rtl::fsm::Fsm;
use crate::rtl::{Module, Ty};
use crate::scene::rom::value_bits;

crate::states! {
    /// The generator's states, in encoding order.
    pub enum GenState {
        /// The reciprocals of the current pixel's direction.
        Div = "div",
        /// `ray_valid` until the core takes the ray.
        Full = "full",
        /// After the last pixel.
        Done = "done",
    }
}

/// Ports: `ready` in; `ray_valid`, `ray_id`, `ox oy oz`, `wx wy wz`, `invx invy invz` out (the
/// core's ray inputs, in `top::core_inputs` order).
pub fn raygen_core(g: &RayGen, n: u32, m_bits: u32, c: u32, id_width: u32) -> Module {
    generator(g, n, m_bits, c, id_width, false)
}

/// The generator that starts the frame again (`fxrt_raygen_restart`, for the board tops): a
/// second input `restart`, taken in `done`, returns it to the first pixel with ray id 0.
pub fn raygen_restart_core(g: &RayGen, n: u32, m_bits: u32, c: u32, id_width: u32) -> Module {
    generator(g, n, m_bits, c, id_width, true)
}

fn generator(g: &RayGen, n: u32, m_bits: u32, c: u32, id_width: u32, restarts: bool) -> Module {
    use GenState::*;
    let b = Builder::new(if restarts { "fxrt_raygen_restart" } else { "fxrt_raygen" });
    let f = m_bits - 1;
    let qbits = f + c + 1;
    let ready = b.input("ready", Ty::BIT);
    let restart = restarts.then(|| b.input("restart", Ty::BIT));
    let fsm = Fsm::new(&b, "state", "pinhole rays, pixel after pixel", Div);

    // Pixel counters and the direction, stepped when a ray is taken.
    let px = b.reg("px", Ty::u(value_bits(g.width as usize)), Some(0));
    let py = b.reg("py", Ty::u(value_bits(g.height as usize)), Some(0));
    let id = b.reg("pixel", Ty::u(id_width), Some(0));
    let last_x = px.eq(g.width as i128 - 1).name("last_x");
    let last = (last_x & py.eq(g.height as i128 - 1)).name("last_pixel");
    // Directions in m + 2 bits, so no step in or just past the frame wraps.
    let dw = Ty::s(m_bits + 2);
    let axes = ["x", "y", "z"];
    let row = [0, 1, 2].map(|k| b.reg(&format!("row_{}", axes[k]), dw, Some(g.d0[k] as i128)));
    let d = [0, 1, 2].map(|k| b.reg(&format!("d_{}", axes[k]), dw, Some(g.d0[k] as i128)));
    let row_next = [0, 1, 2].map(|k| row[k] + g.dy[k] as i128);
    let w_out = d.map(|d| d.resize(m_bits));

    // Three restoring dividers: q = floor(2^(F+C) / |w|), |w| = 1 for w = 0; one quotient bit
    // per clock, the numerator's only 1 (its top bit) shifted in first. The divisor |w| comes
    // from a register, loaded in the first clock of `div` (count 0), so a step is one
    // compare-subtract between registers (negating w in the same clock was the slowest path of
    // the ULX3S board top: 98.9 MHz).
    let count = b.reg("div_count", Ty::u(value_bits(qbits as usize + 1)), Some(0));
    let first_bit = count.eq(1).name("first_bit");
    let lim = (1i128 << (m_bits + c - 1)) - 1;
    let rem = axes.map(|a| b.reg(&format!("rem_{a}"), Ty::u(f + 2), Some(0)));
    let quot = axes.map(|a| b.reg(&format!("quot_{a}"), Ty::u(qbits), Some(0)));
    let mut steps = Vec::new();
    let mut inv_out = Vec::new();
    for k in 0..3 {
        let w = w_out[k];
        let neg = w.lt(0).name(&format!("neg_{}", axes[k]));
        let mag = neg.select(-w, w).unsigned().resize(f + 2);
        let divisor = b.delay(&format!("b_{}", axes[k]), w.eq(0).select(mag.k(1), mag));
        let r3 = (first_bit.select(rem[k].k(0), rem[k]) << 1) + first_bit.resize(f + 2);
        let ge = divisor.le(r3);
        let r_next = ge.select(r3 - divisor, r3);
        let q_next = (first_bit.select(quot[k].k(0), quot[k]) << 1) + ge.resize(qbits);
        steps.push((r_next, q_next));
        // Saturate to the m + C-bit range, then the sign.
        let q = quot[k];
        let q_s = q.gt(lim).select(q.k(lim), q).resize(m_bits + c).signed();
        inv_out.push(neg.select(-q_s, q_s).name(&format!("inv_{}", axes[k])));
    }

    fsm.state(Div, |s| {
        s.set(count, count + 1);
        s.when(count.ne(0), |s| {
            for k in 0..3 {
                s.set(rem[k], steps[k].0);
                s.set(quot[k], steps[k].1);
            }
        });
        s.when(count.eq(qbits as i128), |s| s.goto(Full));
    });
    fsm.state(Full, |s| {
        s.set_k(count, 0);
        s.when(ready, |s| {
            s.set(id, id + 1);
            s.when(last_x, |s| {
                s.set_k(px, 0);
                s.set(py, py + 1);
                for k in 0..3 {
                    s.set(row[k], row_next[k]);
                    s.set(d[k], row_next[k]);
                }
            })
            .otherwise(|s| {
                s.set(px, px + 1);
                for k in 0..3 {
                    s.set(d[k], d[k] + g.dx[k] as i128);
                }
            });
            s.when(last, |s| s.goto(Done)).otherwise(|s| s.goto(Div));
        });
    });
    fsm.state(Done, |s| {
        s.set_k(count, 0);
        if let Some(restart) = restart {
            s.when(restart, |s| {
                s.set_k(px, 0);
                s.set_k(py, 0);
                s.set_k(id, 0);
                for k in 0..3 {
                    s.set_k(row[k], g.d0[k] as i128);
                    s.set_k(d[k], g.d0[k] as i128);
                }
                s.goto(Div);
            });
        }
    });
    let in_full = fsm.is(Full);
    fsm.finish();

    b.output("ray_valid", in_full);
    b.output("ray_id", id);
    for (k, name) in ["ox", "oy", "oz"].iter().enumerate() {
        b.output(name, b.konst_named(&format!("eye_{name}"), Ty::u(n), g.eye[k] as i128));
    }
    for (name, w) in ["wx", "wy", "wz"].iter().zip(w_out) {
        b.output(name, w);
    }
    for (name, inv) in ["invx", "invy", "invz"].iter().zip(inv_out) {
        b.output(name, inv);
    }
    b.finish()
}

/// A camera inside the Cornell box, looking at the back wall (the generator's tests, here and
/// in `verify::core_tests`).
#[cfg(test)]
pub(crate) fn inside_cornell() -> (crate::scene::Scene, crate::model::camera::Camera) {
    use crate::scene::{Scene, SceneSource};
    let scene = Scene::load(&SceneSource::Builtin("cornell".into()), &crate::params::Params::default()).unwrap();
    let mut cam = crate::model::camera::Camera::default_for(&scene, 12, 10);
    cam.eye = [278.0, 273.0, 60.0];
    cam.at = [300.0, 250.0, 559.0];
    (scene, cam)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::camera::Camera;
    use crate::model::golden::Golden;
    use crate::params::Params;
    use crate::rtl::sim::Sim;
    use crate::scene::{Scene, SceneSource};

    #[test]
    fn emits_the_golden_rays_in_pixel_order() {
        let (scene, cam) = inside_cornell();
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
    fn a_camera_outside_the_box_is_refused() {
        let scene = Scene::load(&SceneSource::Builtin("cornell".into()), &Params::default()).unwrap();
        let cam = Camera::default_for(&scene, 8, 8);
        assert_eq!(RayGen::new(&scene, &cam).unwrap_err().0, "eye");
    }
}
