//! The AXI4-Stream wrapper in the cycle simulator: whole frames with a source and a sink that
//! stall at random (seeded), every result against the golden model, the frame barrier and
//! `tlast`, the AXI rule that a result offered stays offered, and no combinational path from
//! an input to an output. (Here beside the host side, `axis_host`, which packs its rays and
//! unpacks its results.)

use crate::cores::axis::{Layout, axis_module, part_names};
use crate::cores::top::{CoreParams, core_module};
use crate::generate::axis_host::{pack_ray, unpack_result};
use crate::model::camera::Camera;
use crate::model::golden::Hit;
use crate::params::Params;
use crate::rng::SplitMix64;
use crate::rtl::sim::Sim;
use crate::rtl::{Module, Ty};
use crate::scene::images::SceneRoms;
use crate::scene::{Scene, SceneSource};
use crate::verify::frame::{PixelRay, frame_rays, mismatches};
use std::rc::Rc;

struct Setup {
    scene: Scene,
    p: CoreParams,
    wrapper: Module,
    layout: Layout,
}

fn setup(name: &str, n: u32, m: u32) -> Setup {
    let scene = Scene::load(&SceneSource::Builtin(name.into()), &Params { n, m, ..Params::default() }).unwrap();
    let roms = SceneRoms::of(&scene);
    let p = CoreParams::new(&roms, 16, 1, crate::cores::clock::DEFAULT_TARGET_MHZ);
    let core = Rc::new(core_module(&p, &roms));
    let wrapper = axis_module(&core, &p);
    Setup { scene, p, wrapper, layout: Layout::of(&core) }
}

/// What came out of the result port: each result with its `tlast`.
struct Outcome {
    results: Vec<(u64, Option<Hit>)>,
    lasts: Vec<bool>,
    cycles: u64,
    /// Cycles the source offered a ray the wrapper did not take, and the sink refused a result.
    source_waits: u64,
    sink_stalls: u64,
}

/// Streams `rays` into the wrapper, a frame ending (`tlast`) every `frame` rays and at the end
/// when given. The source offers its next ray on `valid_pct` % of the cycles it is not already
/// offering one and then holds it until taken (AXI4-Stream); the sink is ready on `ready_pct`
/// % of the cycles. Runs until every ray has a result and 300 cycles more. With `scramble`,
/// every register and RAM starts random (`Sim::scramble`) and `rst` is high for the first
/// clock.
fn stream(s: &Setup, rays: &[PixelRay], frame: Option<usize>, pct: (u64, u64), seed: u64, scramble: bool) -> Outcome {
    let (valid_pct, ready_pct) = pct;
    let m = &s.wrapper;
    let input = |name: &str| m.handle(*m.inputs.iter().find(|&&i| m.sig(i).name == name).expect(name));
    let output = |name: &str| m.handle(m.outputs.iter().find(|o| o.0 == name).expect(name).1);
    let ray_parts: Vec<_> = part_names("s_axis_ray_tdata", s.layout.ray_bytes).iter().map(|n| input(n)).collect();
    let res_parts: Vec<_> = part_names("m_axis_res_tdata", s.layout.res_bytes).iter().map(|n| output(n)).collect();
    let (s_valid, s_last, m_ready) =
        (input("s_axis_ray_tvalid"), input("s_axis_ray_tlast"), input("m_axis_res_tready"));
    let (s_ready, m_valid, m_last) =
        (output("s_axis_ray_tready"), output("m_axis_res_tvalid"), output("m_axis_res_tlast"));
    let mut sim = Sim::new(m);
    if scramble {
        sim.scramble(seed);
        sim.reset = true;
        sim.tick();
        sim.reset = false;
    }
    let mut rng = SplitMix64(seed);
    let mut out = Outcome { results: Vec::new(), lasts: Vec::new(), cycles: 0, source_waits: 0, sink_stalls: 0 };
    let (mut next, mut offering) = (0usize, false);
    // A result offered and refused, which must stay on the port unchanged.
    let mut refused: Option<(Vec<u8>, bool)> = None;
    let mut done_at: Option<u64> = None;
    while done_at.is_none_or(|d| out.cycles < d + 300) {
        assert!(out.cycles < 400 * rays.len() as u64 + 10_000, "the wrapper stopped: {} results", out.results.len());
        if !offering && next < rays.len() {
            offering = rng.below(100) < valid_pct;
        }
        sim.set(s_valid, offering as i128);
        if let Some(r) = rays.get(next) {
            let bytes = pack_ray(&s.layout, r.pixel as u64, &r.ray);
            for (k, &port) in ray_parts.iter().enumerate() {
                sim.set(port, u64::from_le_bytes(bytes[8 * k..8 * k + 8].try_into().unwrap()) as i128);
            }
            let last = frame.is_some_and(|f| (next + 1) % f == 0 || next + 1 == rays.len());
            sim.set(s_last, last as i128);
        }
        let ready = rng.below(100) < ready_pct;
        sim.set(m_ready, ready as i128);
        sim.eval();
        let valid = sim.get(m_valid) == 1;
        let bytes: Vec<u8> = res_parts.iter().flat_map(|&p| (sim.get(p) as u64).to_le_bytes()).collect();
        let last = sim.get(m_last) == 1;
        if let Some(was) = refused.take() {
            assert!(valid && was == (bytes.clone(), last), "cycle {}: a refused result changed or left", out.cycles);
        }
        if valid && ready {
            let (id, hit) = unpack_result(&s.layout, &bytes);
            out.results.push((id, hit));
            out.lasts.push(last);
        } else if valid {
            refused = Some((bytes, last));
            out.sink_stalls += 1;
        }
        if offering {
            if sim.get(s_ready) == 1 {
                next += 1;
                offering = false;
            } else {
                out.source_waits += 1;
            }
        }
        sim.tick();
        out.cycles += 1;
        if done_at.is_none() && out.results.len() >= rays.len() {
            done_at = Some(out.cycles);
        }
    }
    out
}

/// Every result right and each ray's once; with frames, each frame's results (as a set) before
/// its `tlast`, which is on its last result only; without, no `tlast`.
fn check(s: &Setup, rays: &[PixelRay], frame: Option<usize>, o: &Outcome) {
    assert_eq!(mismatches(&s.scene, rays, &o.results), 0, "results against the golden model");
    assert_eq!(o.results.len(), rays.len(), "one result per ray");
    let Some(f) = frame else {
        assert!(o.lasts.iter().all(|&l| !l), "tlast without a frame");
        return;
    };
    let ends: Vec<usize> = (0..o.lasts.len()).filter(|&k| o.lasts[k]).collect();
    let want: Vec<usize> = (0..rays.len()).filter(|&k| (k + 1) % f == 0 || k + 1 == rays.len()).collect();
    assert_eq!(ends, want, "tlast on each frame's last result");
    for (k, chunk) in rays.chunks(f).enumerate() {
        let mut sent: Vec<u64> = chunk.iter().map(|r| r.pixel as u64).collect();
        let mut got: Vec<u64> = o.results[k * f..k * f + chunk.len()].iter().map(|r| r.0).collect();
        sent.sort_unstable();
        got.sort_unstable();
        assert_eq!(got, sent, "frame {k}: its results, and only those, before its tlast");
    }
}

#[test]
fn frames_stream_through_with_random_valid_and_ready() {
    let s = setup("cornell", 29, 32);
    assert_eq!((s.layout.ray_bytes, s.layout.res_bytes), (64, 16));
    let rays = crate::verify::feed::feed_order(&frame_rays(&s.scene, &Camera::default_for(&s.scene, 16, 16)), Some(5));
    for (frame, seed) in [(None, 1), (Some(60), 2), (Some(1), 3)] {
        let o = stream(&s, &rays, frame, (60, 50), seed, false);
        check(&s, &rays, frame, &o);
        assert!(o.source_waits > 0 && o.sink_stalls > 0, "both sides stalled: {} {}", o.source_waits, o.sink_stalls);
    }
}

/// The barrier costs one drain of the core per frame: a frame per ray is far slower than one
/// frame, which is as fast as no frame at all.
#[test]
fn the_barrier_drains_the_core_once_per_frame() {
    // Directions and reciprocals with sign extension inside their bytes (27 and 43 bits).
    let s = setup("cornell", 23, 27);
    assert_eq!((s.layout.ray_bytes, s.layout.res_bytes), (64, 16));
    let rays = frame_rays(&s.scene, &Camera::default_for(&s.scene, 8, 8));
    let free = stream(&s, &rays, None, (100, 100), 4, false);
    let whole = stream(&s, &rays, Some(rays.len()), (100, 100), 4, false);
    let each = stream(&s, &rays, Some(1), (100, 100), 4, false);
    for (frame, o) in [(None, &free), (Some(rays.len()), &whole), (Some(1), &each)] {
        check(&s, &rays, frame, o);
    }
    assert_eq!(whole.cycles, free.cycles);
    assert!(each.cycles > 3 * free.cycles, "{} vs {}", each.cycles, free.cycles);
    assert!(s.p.slot_count() > 1);
}

/// One clock of `rst` from any state (every register and RAM random) and the wrapper works:
/// its count, frame flag and register slice start empty, as the core's valid bits do.
#[test]
fn one_clock_of_reset_from_any_state_starts_clean() {
    let s = setup("cornell", 16, 16);
    let rays = frame_rays(&s.scene, &Camera::default_for(&s.scene, 8, 8));
    for seed in [1, 2, 3] {
        let o = stream(&s, &rays, Some(20), (60, 50), seed, true);
        check(&s, &rays, Some(20), &o);
    }
}

/// The inputs each output depends on within one clock (through any logic of the core too).
fn comb_paths(m: &Module) -> Vec<(String, String)> {
    use crate::rtl::netlist::Def;
    let flat = crate::rtl::flatten::flatten(m);
    let inputs: Vec<(usize, &str)> =
        m.inputs.iter().map(|&i| (flat.top[i.0 as usize], m.sig(i).name.as_str())).collect();
    // The inputs (bit k: input k) each slot depends on combinationally, in evaluation order.
    let mut deps = vec![0u128; flat.defs.len()];
    for (k, &(slot, _)) in inputs.iter().enumerate() {
        deps[slot] = 1 << k;
    }
    for &slot in &flat.comb_order {
        deps[slot] = flat.defs[slot].comb_inputs().iter().fold(0, |acc, d| acc | deps[d.0 as usize]);
        if matches!(flat.defs[slot], Def::Input) {
            unreachable!("inputs are not combinational");
        }
    }
    let mut paths = Vec::new();
    for (name, id) in &m.outputs {
        let d = deps[flat.top[id.0 as usize]];
        paths.extend((0..inputs.len()).filter(|&k| d >> k & 1 == 1).map(|k| (inputs[k].1.to_string(), name.clone())));
    }
    paths
}

#[test]
fn no_output_depends_on_an_input_in_the_same_clock() {
    let s = setup("cornell", 16, 16);
    assert!(s.wrapper.inputs.len() <= 128);
    assert_eq!(comb_paths(&s.wrapper), Vec::<(String, String)>::new());
    // The check sees a path where there is one: the core's ray port has none, a ray_valid
    // gated by ray_ready would.
    let b = crate::rtl::build::Builder::new("probe");
    let (a, c) = (b.input("a", Ty::BIT), b.input("c", Ty::BIT));
    let r = b.reg("r", Ty::BIT, Some(0));
    b.next(r, a);
    b.output("y", (a & r).name("y_c"));
    b.output("z", r | c);
    b.output("q", r);
    assert_eq!(comb_paths(&b.finish()), [("a".to_string(), "y".to_string()), ("c".into(), "z".into())]);
}

/// Both printers show each tdata as one port, its parts as slices of it.
#[test]
fn tdata_is_one_port_in_both_languages() {
    let s = setup("cornell", 16, 16);
    let vhdl = crate::rtl::emit::vhdl::print(&s.wrapper);
    assert!(vhdl.contains("s_axis_ray_tdata : in std_logic_vector(255 downto 0);"), "{vhdl}");
    assert!(vhdl.contains("m_axis_res_tdata : out std_logic_vector(127 downto 0);"));
    assert!(vhdl.contains("s_axis_ray_tdata_3 <= unsigned(s_axis_ray_tdata(255 downto 192));"));
    assert!(vhdl.contains("m_axis_res_tdata(127 downto 64) <= std_logic_vector(res_tdata_1);"));
    assert!(!vhdl.contains("s_axis_ray_tdata_0 : in"));
    let verilog = crate::rtl::emit::verilog::print(&s.wrapper);
    assert!(verilog.contains("input wire [255:0] s_axis_ray_tdata,"), "{verilog}");
    assert!(verilog.contains("output wire [127:0] m_axis_res_tdata,"));
    assert!(verilog.contains("assign s_axis_ray_tdata_3 = s_axis_ray_tdata[255:192];"));
    assert!(verilog.contains("assign m_axis_res_tdata[127:64] = res_tdata_1;"));
    assert!(s.wrapper.name.ends_with("_axis") && s.wrapper.name.starts_with(&s.wrapper.instances[0].module.name));
}

/// The wrapper's shortest latency is the core's plus `AXIS_ADDED_LATENCY` (its output
/// register), the figure its manifest gives: the box-missing ray offered to an idle wrapper
/// whose sink is always ready, counted from the clock it is taken to the clock its result is
/// offered.
#[test]
fn the_wrapper_adds_its_output_register_to_the_shortest_latency() {
    use crate::cores::axis::AXIS_ADDED_LATENCY;
    use crate::verify::disturb::{min_latency, min_latency_ray};
    let s = setup("cornell", 16, 16);
    let roms = SceneRoms::of(&s.scene);
    let core_min = min_latency(&core_module(&s.p, &roms), &s.p, &roms).expect("room on an axis");
    let m = &s.wrapper;
    let input = |name: &str| m.handle(*m.inputs.iter().find(|&&i| m.sig(i).name == name).expect(name));
    let output = |name: &str| m.handle(m.outputs.iter().find(|o| o.0 == name).expect(name).1);
    let mut sim = Sim::new(m);
    let bytes = pack_ray(&s.layout, 0, &min_latency_ray(&s.p, &roms).unwrap());
    for (k, name) in part_names("s_axis_ray_tdata", s.layout.ray_bytes).iter().enumerate() {
        sim.set(input(name), u64::from_le_bytes(bytes[8 * k..8 * k + 8].try_into().unwrap()) as i128);
    }
    sim.set(input("m_axis_res_tready"), 1);
    let mut taken = None;
    let latency = (0..10_000u64).find_map(|cycle| {
        sim.set(input("s_axis_ray_tvalid"), taken.is_none() as i128);
        sim.eval();
        if sim.get(output("m_axis_res_tvalid")) == 1 {
            return Some(cycle - taken.expect("a result after the ray"));
        }
        if taken.is_none() && sim.get(output("s_axis_ray_tready")) == 1 {
            taken = Some(cycle);
        }
        sim.tick();
        None
    });
    assert_eq!(latency, Some(core_min + AXIS_ADDED_LATENCY), "the core's shortest latency is {core_min}");
}
