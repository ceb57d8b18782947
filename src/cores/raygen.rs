//! The on-chip pinhole ray generator (the thesis's demo): pixel after pixel, the ray of
//! `model::raygen::RayGen` — origin the eye's grid point, direction d0 + px·dx + py·dy — with
//! its three reciprocals from restoring dividers (one quotient bit per clock, F + C + 1 of
//! them). One divider set takes F + C + 2 clocks a ray, the core one ray every ~4–10 clocks, so
//! there are `dividers(..)` sets, dealt pixels in turn and emptied in the same turn: rays leave
//! in pixel order, one every 2 clocks when the sets are ahead of the core.
//!
//! A pixel walker loads the next pixel's direction into the set whose turn it is once that
//! set is empty; the set divides; the set at the output turn hands its ray to the port's two
//! registers once the first is empty and the turn moves on. The core's `ready` only empties
//! the port, so no path runs from the core into the sets (the first version, without the
//! registers, missed the ULX3S board's 80 MHz). After the last pixel the walker stops
//! (`restart`, when every set and both registers are empty, starts the frame again).

use crate::model::raygen::RayGen;
use crate::rtl::build::{Builder, S};
use crate::rtl::{Module, Ty};
use crate::scene::rom::value_bits;

/// A ray every this many clocks at least, from `dividers` sets: ahead of the core with up to
/// four intersection pipelines (about a ray every 2.5 clocks at 0.4 rays per clock would need
/// more; the teapot's core takes one every ~10).
pub const CLOCKS_PER_RAY: u32 = 4;

/// Divider sets for quotients of `qbits` bits: each takes qbits + 2 clocks a ray (a load, the
/// bits, the hand-over), so this many give a ray every `CLOCKS_PER_RAY` clocks.
pub fn dividers(qbits: u32) -> u32 {
    (qbits + 2).div_ceil(CLOCKS_PER_RAY)
}

/// Ports: `ready` in; `ray_valid`, `ray_id`, `ox oy oz`, `wx wy wz`, `invx invy invz` out (the
/// core's ray inputs, in `top::core_inputs` order).
pub fn raygen_core(g: &RayGen, n: u32, m_bits: u32, c: u32, id_width: u32) -> Module {
    generator(g, n, m_bits, c, id_width, false)
}

/// The generator that starts the frame again (`fxrt_raygen_restart`, for the board tops): a
/// second input `restart`, taken once every ray of the frame has left (from the clock after the
/// port empties; a pulse earlier is ignored), returns it to the first pixel with ray id 0.
pub fn raygen_restart_core(g: &RayGen, n: u32, m_bits: u32, c: u32, id_width: u32) -> Module {
    generator(g, n, m_bits, c, id_width, true)
}

fn generator(g: &RayGen, n: u32, m_bits: u32, c: u32, id_width: u32, restarts: bool) -> Module {
    let b = Builder::new(if restarts { "fxrt_raygen_restart" } else { "fxrt_raygen" });
    let f = m_bits - 1;
    let qbits = f + c + 1;
    let sets = dividers(qbits);
    let turn_ty = Ty::u(value_bits(sets as usize));
    let ready = b.input("ready", Ty::BIT);
    let restart = restarts.then(|| b.input("restart", Ty::BIT));
    let axes = ["x", "y", "z"];

    // The pixel walker: the next pixel to load, its direction (m + 2 bits, so no step in or
    // just past the frame wraps), and whether the frame's pixels are all loaded.
    b.stage("walk", "the next pixel to load into a divider set");
    let px = b.reg("px", Ty::u(value_bits(g.width as usize)), Some(0));
    let py = b.reg("py", Ty::u(value_bits(g.height as usize)), Some(0));
    let walked = b.reg("walked", Ty::BIT, Some(0));
    let last_x = px.eq(g.width as i128 - 1).name("last_x");
    let last = (last_x & py.eq(g.height as i128 - 1)).name("last_pixel");
    let dw = Ty::s(m_bits + 2);
    let row = [0, 1, 2].map(|k| b.reg(&format!("row_{}", axes[k]), dw, Some(g.d0[k] as i128)));
    let d = [0, 1, 2].map(|k| b.reg(&format!("d_{}", axes[k]), dw, Some(g.d0[k] as i128)));
    let row_next = [0, 1, 2].map(|k| row[k] + g.dy[k] as i128);
    let load_turn = b.reg("load_turn", turn_ty, Some(0));
    let out_turn = b.reg("out_turn", turn_ty, Some(0));
    let out_id = b.reg("ray_id_next", Ty::u(id_width), Some(0));

    // Each set: its direction, |w| (1 for w = 0), remainder and quotient, and whether it is
    // dividing (`run`, with the bit count) or holds a finished ray (`held`).
    b.stage("divide", "restoring dividers: q = floor(2^(F+C) / |w|), a bit a clock");
    let lim = (1i128 << (m_bits + c - 1)) - 1;
    let mut load = Vec::new();
    let mut busy = Vec::new();
    let mut held_next = Vec::new();
    let mut outs = Vec::new();
    let take = b.wire("take", Ty::BIT);
    for s in 0..sets {
        let is_load = load_turn.eq(s as i128);
        let run = b.reg(&format!("run{s}"), Ty::BIT, Some(0));
        let hold = b.reg(&format!("held{s}"), Ty::BIT, Some(0));
        let idle = (!run & !hold).name(&format!("idle{s}"));
        let loads = (is_load & idle & !walked).name(&format!("load{s}"));
        let count = b.reg(&format!("count{s}"), Ty::u(value_bits(qbits as usize + 1)), Some(0));
        let first = count.eq(1).name(&format!("first{s}"));
        let ends = (run & count.eq(qbits as i128)).name(&format!("ends{s}"));
        let taken = (take & out_turn.eq(s as i128)).name(&format!("taken{s}"));
        b.next(run, loads.select(run.k(1), ends.select(run.k(0), run)));
        let hold_next = ends.select(hold.k(1), taken.select(hold.k(0), hold)).name(&format!("held_next{s}"));
        b.next(hold, hold_next);
        held_next.push(hold_next);
        b.next(count, loads.select(count.k(1), run.select(count + 1, count)));
        let mut set_out = Vec::new();
        for (k, axis) in axes.iter().enumerate() {
            let w_new = d[k].resize(m_bits);
            let w = b.reg(&format!("w{s}_{axis}"), Ty::s(m_bits), Some(0));
            b.next_when(w, loads, w_new);
            let neg = w_new.lt(0);
            let mag = neg.select(-w_new, w_new).unsigned().resize(f + 2);
            let divisor = b.reg(&format!("b{s}_{axis}"), Ty::u(f + 2), Some(0));
            b.next_when(divisor, loads, w_new.eq(0).select(mag.k(1), mag));
            let rem = b.reg(&format!("rem{s}_{axis}"), Ty::u(f + 2), Some(0));
            let quot = b.reg(&format!("quot{s}_{axis}"), Ty::u(qbits), Some(0));
            // Area (13 sets × 3 axes of these): the remainder is cleared at the load, so the
            // shift is a wiring; the numerator's only 1 (its top bit) enters with the first
            // quotient bit; one subtractor, its borrow the compare; the quotient needs no
            // clearing (its qbits shifts push the last ray's bits out).
            let r3 = b.cat(&[rem.slice(0, f + 1), first]);
            let diff = (r3.resize(f + 3) - divisor.resize(f + 3)).name(&format!("diff{s}_{axis}"));
            let fits = !diff.msb();
            b.next(rem, loads.select(rem.k(0), run.select(fits.select(diff.resize(f + 2), r3), rem)));
            let shifted = if qbits > 1 { b.cat(&[quot.slice(0, qbits - 1), fits]) } else { fits };
            b.next_when(quot, run, shifted);
            set_out.push((w, quot));
        }
        load.push(loads);
        busy.push(!idle);
        outs.push(set_out);
    }
    let loaded = load.iter().copied().reduce(|a, x| a | x).expect("a set").name("loaded");
    let any_busy = busy.iter().copied().reduce(|a, x| a | x).expect("a set").name("any_busy");

    // The walker steps when its pixel is loaded.
    b.stage("step", "the walker steps past a loaded pixel");
    let wrap = |t| next_turn(t, sets);
    // The port's two registers (below) hold rays until the core takes them: a frame ends when
    // they are empty too.
    let pick_valid = b.reg("pick_valid", Ty::BIT, Some(0));
    let port_valid = b.reg("port_valid", Ty::BIT, Some(0));
    // Whether the frame has ended, in a register (`restart` through the whole of it into the
    // stepping registers' resets was the board's slowest path after the divider cut: 78.7
    // MHz). Once true it stays true until a restart, so a clock's delay only delays the
    // restart; the register drops with the restart, so a held `restart` does not repeat it
    // before the walk is under way.
    let restarting = match restart {
        Some(r) => {
            let quiet = b.reg("frame_done", Ty::BIT, Some(0));
            let restarting = (r & quiet).name("restarting");
            let done_now = walked & !any_busy & !pick_valid & !port_valid;
            b.next(quiet, done_now & !restarting);
            restarting
        }
        None => b.konst(Ty::BIT, 0),
    };
    b.next(load_turn, restarting.select(load_turn.k(0), loaded.select(wrap(load_turn), load_turn)));
    b.next(out_turn, restarting.select(out_turn.k(0), take.select(wrap(out_turn), out_turn)));
    b.next(out_id, restarting.select(out_id.k(0), take.select(out_id + 1, out_id)));
    b.next(walked, restarting.select(walked.k(0), (loaded & last).select(walked.k(1), walked)));
    b.next(px, restarting.select(px.k(0), loaded.select(last_x.select(px.k(0), px + 1), px)));
    b.next(py, restarting.select(py.k(0), (loaded & last_x).select(py + 1, py)));
    for k in 0..3 {
        let d0 = d[k].k(g.d0[k] as i128);
        b.next(row[k], restarting.select(d0, (loaded & last_x).select(row_next[k], row[k])));
        let stepped = last_x.select(row_next[k], d[k] + g.dx[k] as i128);
        b.next(d[k], restarting.select(d0, loaded.select(stepped, d[k])));
    }

    // The ray port, two registers deep: the set at the output turn hands its ray to `pick`
    // while that is empty (the 13-way select ends there), `pick` moves to the port while the
    // port is empty (saturation and sign end there), and the core's `ready` only empties the
    // port — no path runs from the core into the sets, and none through both the select and
    // the carry chains (a ray every 2 clocks at most, twice what `CLOCKS_PER_RAY` needs).
    b.stage("port", "the finished ray of the set at the output turn, in two registers");
    let pick = |v| pick_set(&b, out_turn, v);
    // Whether the set at the output turn holds a ray, in a register (its 13-way select by the
    // turn, then the enables of every `pick` register, was the board's slowest path: 78 MHz):
    // next clock's turn is this one or the one after, so both selects are made and `take` picks.
    let turn_held = b.reg("turn_held", Ty::BIT, Some(0));
    let held_here = pick(held_next.clone());
    let held_after = pick_set(&b, wrap(out_turn), held_next.clone());
    b.next(turn_held, restarting.select(turn_held.k(0), take.select(held_after, held_here)));
    let handing = (turn_held & !pick_valid).name("hand_over");
    let moving = (pick_valid & !port_valid).name("to_port");
    b.drive(take, handing);
    b.next(pick_valid, handing.select(pick_valid.k(1), moving.select(pick_valid.k(0), pick_valid)));
    b.next(port_valid, moving.select(port_valid.k(1), port_valid & !ready));
    let pick_id = b.reg("pick_id", Ty::u(id_width), Some(0));
    b.next_when(pick_id, handing, out_id);
    let port_id = b.reg("port_id", Ty::u(id_width), Some(0));
    b.next_when(port_id, moving, pick_id);
    let mut port_w = Vec::new();
    let mut port_inv = Vec::new();
    for (k, axis) in axes.iter().enumerate() {
        let w_pick = b.reg(&format!("pick_w{axis}"), Ty::s(m_bits), Some(0));
        b.next_when(w_pick, handing, pick(outs.iter().map(|o| o[k].0).collect()));
        let q = b.reg(&format!("pick_q{axis}"), Ty::u(qbits), Some(0));
        b.next_when(q, handing, pick(outs.iter().map(|o| o[k].1).collect()));
        let w = b.reg(&format!("port_w{axis}"), Ty::s(m_bits), Some(0));
        b.next_when(w, moving, w_pick);
        // Saturate to the m + C-bit range, then the sign.
        let q_s = q.gt(lim).select(q.k(lim), q).resize(m_bits + c).signed();
        let inv = b.reg(&format!("port_inv{axis}"), Ty::s(m_bits + c), Some(0));
        b.next_when(inv, moving, w_pick.lt(0).select(-q_s, q_s));
        port_w.push(w);
        port_inv.push(inv);
    }
    b.end_stage();
    b.output("ray_valid", port_valid);
    b.output("ray_id", port_id);
    for (k, name) in ["ox", "oy", "oz"].iter().enumerate() {
        b.output(name, b.konst_named(&format!("eye_{name}"), Ty::u(n), g.eye[k] as i128));
    }
    for (name, w) in ["wx", "wy", "wz"].iter().zip(&port_w) {
        b.output(name, *w);
    }
    for (name, inv) in ["invx", "invy", "invz"].iter().zip(&port_inv) {
        b.output(name, *inv);
    }
    b.finish()
}

/// The turn after `t` among `sets`.
fn next_turn(t: S<'_>, sets: u32) -> S<'_> {
    t.eq(sets as i128 - 1).select(t.k(0), t + 1)
}

/// `v[turn]`: one value of each divider set.
fn pick_set<'b>(b: &'b Builder, turn: S<'b>, v: Vec<S<'b>>) -> S<'b> {
    let arms: Vec<(u128, S)> = v.iter().enumerate().skip(1).map(|(i, &x)| (i as u128, x)).collect();
    b.case(turn, &arms, v[0])
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

    /// Drives the inside-Cornell restarting generator for `cycles` clocks, `ready` and
    /// `restart` given by the clock, and checks each ray taken (valid while ready) against the
    /// golden ray of the pixel it should be: the frames one after another, in pixel order, each
    /// pixel once (its id, `invz`, `wx` and `wy`). Returns the clocks the rays were taken at,
    /// and the pixels in a frame.
    fn restarting_frames(cycles: u32, ready: impl Fn(u32) -> bool, restart: impl Fn(u32) -> bool) -> (Vec<u32>, u32) {
        let (scene, cam) = inside_cornell();
        let g = Golden::new(&scene);
        let rg = RayGen::new(&scene, &cam).unwrap();
        let p = &scene.params;
        let m = raygen_restart_core(&rg, p.n, p.m, p.c, 8);
        let mut sim = Sim::new(&m);
        let out = |name: &str| m.handle(m.outputs.iter().find(|o| o.0 == name).unwrap().1);
        let (ready_in, restart_in) = (m.handle(m.inputs[0]), m.handle(m.inputs[1]));
        let pixels = cam.width * cam.height;
        let mut taken = Vec::new();
        for cycle in 0..cycles {
            sim.set(ready_in, ready(cycle) as i128);
            sim.set(restart_in, restart(cycle) as i128);
            sim.eval();
            if sim.get(out("ray_valid")) == 1 && ready(cycle) {
                let k = taken.len() as u32 % pixels;
                let want = rg.ray(&g, k % cam.width, k / cam.width);
                let ray = taken.len();
                assert_eq!(sim.get(out("ray_id")), k as i128, "ray {ray}");
                assert_eq!(sim.get(out("invz")), want.inv[2], "ray {ray}");
                assert_eq!(sim.get(out("wx")), want.w[0] as i128, "ray {ray}");
                assert_eq!(sim.get(out("wy")), want.w[1] as i128, "ray {ray}");
                taken.push(cycle);
            }
            sim.tick();
        }
        (taken, pixels)
    }

    /// A consumer that always takes: after the first ray (a load, F + C + 1 bits, the port) the
    /// divider sets hand over a ray every `CLOCKS_PER_RAY` clocks or faster, in pixel order;
    /// the restarting generator starts the frame again once every ray has left.
    #[test]
    fn keeps_up_a_ray_every_few_clocks_and_restarts() {
        let (taken, pixels) = restarting_frames(4_000, |_| true, |cycle| cycle == 1_000);
        assert_eq!(taken.len() as u32, 2 * pixels, "two frames, the second after the restart");
        let p = &inside_cornell().0.params;
        assert!(taken[0] <= p.m + p.c + 4, "the first ray at {}", taken[0]);
        let span = taken[pixels as usize - 1] - taken[0];
        assert!(span <= (pixels - 1) * CLOCKS_PER_RAY, "{pixels} rays in {span} clocks");
        assert!(taken[pixels as usize] > 1_000, "the second frame waits for the restart");
    }

    /// `restart` held high from the start: frame after frame, each in pixel order from ray id
    /// 0 with every pixel once (a restart that repeated while the walk starts again would give
    /// pixel 0 twice), and a consumer that takes one clock in three.
    #[test]
    fn a_held_restart_gives_whole_frames_one_after_another() {
        let (taken, pixels) = restarting_frames(3_000, |cycle| cycle % 3 == 0, |_| true);
        assert!(taken.len() as u32 >= 3 * pixels, "{} rays: three frames at least", taken.len());
    }

    #[test]
    fn a_camera_outside_the_box_is_refused() {
        let scene = Scene::load(&SceneSource::Builtin("cornell".into()), &Params::default()).unwrap();
        let cam = Camera::default_for(&scene, 8, 8);
        assert_eq!(RayGen::new(&scene, &cam).unwrap_err().0, "eye");
    }
}
