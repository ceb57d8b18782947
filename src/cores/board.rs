//! What a board top runs (docs/BOARDS.md): the on-chip ray generator feeding the core, frame
//! after frame, every result mixed into the frame's checksum (`cores::checksum`), and the
//! checksum compared with the golden model's at the end of each frame. The board's own top
//! (`board`) adds the clock from a PLL, the reset synchroniser and the pins.
//!
//! A frame ends when its W·H-th result has been summed; the generator, which has given its
//! last ray by then, starts the next frame a clock later, so the frames' results never mix.
//! Outputs: `led` — bit 0 the last frame's checksum was the golden one, bit 1 some frame's was
//! not (held until reset), bits 7..2 the frame counter's bits `led_shift + 5 .. led_shift` (a
//! frame takes microseconds to milliseconds: the shift makes a bit the eye can follow).
//! With `debug` also `frames` (the counter) and `frame_sum` (the last frame's checksum).

use super::checksum::{mix_pipeline, pack};
use super::top::{CoreParams, core_module_with};
use crate::model::checksum::ResultWidths;
use crate::model::raygen::RayGen;
use crate::rtl::build::Builder;
use crate::rtl::{Module, Ty};
use crate::scene::images::SceneRoms;
use std::rc::Rc;

/// Widths of the frame counter bits shown on the LEDs.
pub const LED_FRAME_BITS: u32 = 6;

/// What the board logic checks and shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoardCheck {
    /// The golden model's checksum of one frame (`model::checksum::frame_checksum`).
    pub golden: u32,
    /// The frame counter bit shown on LED 2.
    pub led_shift: u32,
}

/// The widths of `core`'s result ports.
pub fn result_widths(core: &Module) -> ResultWidths {
    let w = |name: &str| {
        core.outputs.iter().find(|o| o.0 == name).map(|o| core.sig(o.1).ty.width).expect("a result port of the core")
    };
    ResultWidths { id: w("res_id"), tri: w("res_tri"), t: w("res_t"), u: w("res_u"), v: w("res_v") }
}

/// A short tag of a ray generator's camera (its constants), for module names: two cameras'
/// board logic must not share a name in one project.
pub fn camera_tag(g: &RayGen) -> String {
    use sha2::{Digest, Sha256};
    let text = format!("{:?}", (g.eye, g.d0, g.dx, g.dy, g.width, g.height));
    format!("c{}", &format!("{:x}", Sha256::digest(text.as_bytes()))[..6])
}

/// The board logic module `fxrt_board_<scene tag>_<camera tag>`: no inputs but the clock and
/// the reset.
pub fn board_logic(p: &CoreParams, scene: &SceneRoms, g: &RayGen, check: BoardCheck, debug: bool) -> Module {
    let cam = camera_tag(g);
    let b = Builder::new(&format!("fxrt_board_{}_{cam}", p.trav.scene_tag));
    let mut gen_m = super::raygen::raygen_restart_core(g, p.isect.n, p.isect.m, p.trav.c, p.trav.id_width);
    gen_m.name = format!("{}_{cam}", gen_m.name);
    let generator = Rc::new(gen_m);
    let core = Rc::new(core_module_with(p, scene, false));
    let widths = result_widths(&core);
    let ready = b.wire("gen_ready", Ty::BIT);
    let restart = b.reg("restart", Ty::BIT, Some(0));
    let rays = b.instance("u_raygen", &generator, &[ready, restart]);
    let mut ins = rays.all().to_vec();
    // Every result is taken the clock it is shown.
    ins.push(b.konst(Ty::BIT, 1));
    let res = b.instance("u_core", &core, &ins);
    b.drive(ready, res.get("ray_ready"));

    let words =
        pack(&b, &widths, res.get("res_hit"), ["res_id", "res_tri", "res_t", "res_u", "res_v"].map(|n| res.get(n)));
    let (mixed, mix) = mix_pipeline(&b, res.get("res_valid"), &words);

    let pixels = g.width as u64 * g.height as u64;
    let count_bits = crate::scene::rom::value_bits(pixels as usize);
    let u32t = Ty::u(32);
    let count = b.reg("frame_count", Ty::u(count_bits), Some(0));
    let acc = b.reg("frame_acc", u32t, Some(0));
    let sum_now = (acc + mix).name("frame_acc_next");
    let last = (mixed & count.eq(pixels as i128 - 1)).name("frame_last");
    b.next(count, last.select(count.k(0), mixed.select(count + 1, count)));
    b.next(acc, last.select(acc.k(0), mixed.select(sum_now, acc)));
    b.next(restart, last);
    let good = sum_now.eq(check.golden as i128).name("frame_good");
    let ok = b.reg("frame_ok", Ty::BIT, Some(0));
    let bad = b.reg("frame_bad", Ty::BIT, Some(0));
    b.next(ok, last.select(good, ok));
    b.next(bad, bad | (last & !good));
    let frames = b.reg("frames", Ty::u(check.led_shift + LED_FRAME_BITS), Some(0));
    b.next(frames, last.select(frames + 1, frames));
    let frame_sum = b.reg("frame_sum", u32t, Some(0));
    b.next(frame_sum, last.select(sum_now, frame_sum));

    b.output("led", b.cat(&[frames.slice(check.led_shift, LED_FRAME_BITS), bad, ok]).name("led_c"));
    if debug {
        b.output("frames", frames);
        b.output("frame_sum", frame_sum);
    }
    b.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::camera::Camera;
    use crate::model::checksum::frame_checksum;
    use crate::model::golden::Golden;
    use crate::params::Params;
    use crate::rtl::sim::Sim;
    use crate::scene::{Scene, SceneSource};

    /// Two frames on the Cornell box from inside: each frame's checksum is the golden
    /// model's, LED 0 lights and LED 1 stays dark; with a wrong golden constant LED 1 lights.
    #[test]
    fn frames_checksum_to_the_golden_model() {
        let scene = Scene::load(&SceneSource::Builtin("cornell".into()), &Params::default()).unwrap();
        let mut cam = Camera::default_for(&scene, 5, 4);
        cam.eye = [278.0, 273.0, 60.0];
        let g = Golden::new(&scene);
        let rg = RayGen::new(&scene, &cam).unwrap();
        let roms = SceneRoms::of(&scene);
        let p = CoreParams::shaped(
            &roms,
            &crate::cores::top::CoreSpec {
                id_width: 8,
                div_bits: 1,
                target_mhz: crate::cores::clock::DEFAULT_TARGET_MHZ,
                slots: 4,
                units: 1,
                pipelines: 1,
                piece: Default::default(),
            },
        );
        let core = core_module_with(&p, &roms, false);
        let w = result_widths(&core);
        let golden = frame_checksum(
            &w,
            (0..rg.width * rg.height).map(|i| (i as u64, g.trace(&scene, &rg.ray(&g, i % rg.width, i / rg.width)).0)),
        );
        for (wrong, want_led) in [(false, 0b01i128), (true, 0b10)] {
            let check = BoardCheck { golden: golden ^ wrong as u32, led_shift: 0 };
            let m = board_logic(&p, &roms, &rg, check, true);
            let mut sim = Sim::new(&m);
            let out = |name: &str| m.handle(m.outputs.iter().find(|o| o.0 == name).unwrap().1);
            let mut cycles = 0;
            while sim.get(out("frames")) < 2 {
                sim.tick();
                sim.eval();
                cycles += 1;
                assert!(cycles < 40_000, "two frames in 40000 clocks");
            }
            assert_eq!(sim.get(out("frame_sum")) as u32, golden);
            assert_eq!(sim.get(out("led")), 2 << 2 | want_led);
        }
    }
}
