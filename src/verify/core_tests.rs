//! Whole-frame tests of the core, through the frame harness (`verify::frame`): the core's
//! parameters refused or accepted, small frames against the golden model in both engines, each
//! ray's node visits against the culled golden walk, and the core with its ray generator.
//! (Moved here from `cores::top`, `cores::traverse` and `cores::raygen`: a core's unit tests
//! stay beside it; tests that need this layer's harness live in this layer.)

use crate::cores::mul::Piece;
use crate::cores::raygen::inside_cornell;
use crate::cores::top::{CoreParams, core_inputs, core_module, core_with_raygen, ray_inputs};
use crate::model::camera::Camera;
use crate::model::golden::{Closest, Culled, Golden, Visitor};
use crate::model::raygen::RayGen;
use crate::params::Params;
use crate::rtl::sim::Sim;
use crate::scene::images::SceneRoms;
use crate::scene::{Scene, SceneSource};
use crate::verify::disturb::simulate_rust_cycle;
use crate::verify::feed::Stalls;
use crate::verify::frame::{PixelRay, collect_batched, frame_rays, mismatches, simulate_rust};

/// Three units number their slots as 3 × 2^⌈log2 K⌉: 33 slots each need 192 slot numbers,
/// more than the closest-hit unit's 128-bit word (this panicked while building).
#[test]
fn slot_numbers_beyond_the_closest_hit_unit_are_refused_naming_slots() {
    let scene = Scene::load(&SceneSource::Builtin("cornell".into()), &Params::default()).unwrap();
    let roms = SceneRoms::of(&scene);
    let err = CoreParams::shaped(
        &roms,
        &crate::cores::top::CoreSpec {
            id_width: 16,
            div_bits: 1,
            target_mhz: 150,
            slots: 33,
            units: 3,
            pipelines: 1,
            ..Default::default()
        },
    )
    .check()
    .unwrap_err();
    assert_eq!(err.subject, "--slots");
    assert!(err.message.contains("99 ray slots, numbered as 3 × 64"), "{err}");
    CoreParams::shaped(
        &roms,
        &crate::cores::top::CoreSpec {
            id_width: 16,
            div_bits: 1,
            target_mhz: 150,
            slots: 32,
            units: 3,
            pipelines: 1,
            ..Default::default()
        },
    )
    .check()
    .unwrap();
    CoreParams::shaped(
        &roms,
        &crate::cores::top::CoreSpec {
            id_width: 16,
            div_bits: 1,
            target_mhz: 150,
            slots: 42,
            units: 2,
            pipelines: 1,
            ..Default::default()
        },
    )
    .check()
    .unwrap();
}

/// Pipelines come in 1, 2 or 4, each serving units of its own (so dividing the units), and
/// only with the scene on chip; a lane's closest-hit unit numbers its own slots, so two
/// pipelines hold four units of 64 (256 slot numbers).
#[test]
fn pipelines_that_cannot_share_the_units_are_refused_naming_pipelines() {
    let scene = Scene::load(&SceneSource::Builtin("cornell".into()), &Params::default()).unwrap();
    let roms = SceneRoms::of(&scene);
    let shape = |units, pipelines| crate::cores::top::CoreSpec { slots: 64, units, pipelines, ..Default::default() };
    // Six units in two lanes of three would number lane 1's first unit (3 = 0b011) in lane 0.
    for (units, pipelines) in [(2, 3), (3, 2), (1, 2), (2, 4), (4, 0), (6, 2)] {
        let err = CoreParams::shaped(&roms, &shape(units, pipelines)).check().unwrap_err();
        assert_eq!(err.subject, "--pipelines", "{units} units, {pipelines} pipelines");
    }
    let err = CoreParams::shaped(&roms, &shape(4, 1)).check().unwrap_err();
    assert!(err.message.contains("more --pipelines"), "{err}");
    for (units, pipelines) in [(4, 2), (4, 4), (2, 2), (8, 4)] {
        CoreParams::shaped(&roms, &shape(units, pipelines)).check().unwrap();
    }
    let err = CoreParams::shaped(&roms, &shape(9, 1)).check().unwrap_err();
    assert_eq!((err.subject.as_str(), err.message.as_str()), ("--units", "9 is out of range: must be 1..=8"));
    let spec = crate::cores::memory_params::MemorySpec::default();
    let mut external = CoreParams::external(&roms, &shape(2, 1), spec).unwrap();
    external.pipelines = 2;
    assert_eq!(external.check().unwrap_err().subject, "--pipelines");
}

#[test]
fn a_small_frame_matches_the_golden_model() {
    let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &Params::default()).unwrap();
    let roms = SceneRoms::of(&scene);
    let p = CoreParams::new(&roms, 16, 1, crate::cores::clock::DEFAULT_TARGET_MHZ);
    let rays = frame_rays(&scene, &Camera::default_for(&scene, 16, 16));
    let (results, stats) = simulate_rust(&p, &roms, &rays, &Stalls::none(), &|_| {});
    assert_eq!(mismatches(&scene, &rays, &results), 0);
    assert!(results.iter().filter(|r| r.1.is_some()).count() > 20);
    assert!(stats.busy_cycles > 0 && stats.max_stack_depth > 0, "{stats:?}");
    // The batched engine (ray source in the netlist) and the cycle engine (ports driven
    // like a testbench) agree on every result and every count.
    let (cycle_results, cycle_stats) = simulate_rust_cycle(&p, &roms, &rays, &Stalls::none(), &|_| {});
    assert_eq!(cycle_results, results);
    assert_eq!(
        (cycle_stats.cycles, cycle_stats.busy_cycles, cycle_stats.max_stack_depth, cycle_stats.visits),
        (stats.cycles, stats.busy_cycles, stats.max_stack_depth, stats.visits)
    );
}

/// The culled walk's node visits, in order.
struct Visits<'a>(Culled<'a>, Vec<u32>);

impl Visitor for Visits<'_> {
    fn triangle(&mut self, tri: u32, leaf_tmin: i64) {
        self.0.triangle(tri, leaf_tmin)
    }
    fn prune(&self, tmin: i64) -> bool {
        self.0.prune(tmin)
    }
    fn node(&mut self, node: u32) {
        self.1.push(node)
    }
}

/// Streams `rays` through the whole core (every result taken the clock it is shown) and
/// checks that each ray's node visits, seen on the units' observation ports by slot, are
/// those of `Golden::trace_culled`, in its order. Returns the visits seen in the units' N
/// stages and the leaves their G stages sent (a spread core's, DECISIONS 137).
fn assert_walks_are_the_culled_golden_walks(
    label: &str,
    scene: &Scene,
    rays: &[PixelRay],
    mhz: u32,
    slots: u32,
    [units, pipelines]: [u32; 2],
    piece: Piece,
) -> [u64; 2] {
    let g = Golden::new(scene);
    let roms = SceneRoms::of(scene);
    let p = CoreParams::shaped(
        &roms,
        &crate::cores::top::CoreSpec { id_width: 16, div_bits: 1, target_mhz: mhz, slots, units, pipelines, piece },
    );
    let m = core_module(&p, &roms);
    let mut sim = Sim::new(&m);
    let port = |name: &str| {
        let id = m.outputs.iter().find(|o| o.0 == name).map(|o| o.1);
        m.handle(id.or_else(|| m.inputs.iter().copied().find(|&i| m.sig(i).name == name)).unwrap())
    };
    let ins: Vec<_> = core_inputs(&p).iter().map(|(n, _)| port(n)).collect();
    let (ready, res_valid, res_id) = (port("ray_ready"), port("res_valid"), port("res_id"));
    sim.set(port("res_ready"), 1);
    let (accept, accept_id, slot_out) = (port("accept"), port("accept_id"), port("accept_slot"));
    // The node visits in N and, where a parent sends its leaf child, the leaves sent in G.
    let has = |name: &str| m.outputs.iter().any(|o| o.0 == name);
    let visit: Vec<_> = (0..units)
        .flat_map(|u| [format!("visit{u}"), format!("sent{u}")].map(|v| (u, v)))
        .filter(|(_, v)| has(v))
        .map(|(u, v)| {
            (u, v.starts_with("sent") as usize, port(&v), port(&format!("{v}_slot")), port(&format!("{v}_node")))
        })
        .collect();
    let mut walks: Vec<Vec<u32>> = vec![Vec::new(); rays.len()];
    let mut seen = [0u64; 2];
    let mut in_slot = vec![usize::MAX; p.total_slots() as usize];
    let (mut next, mut done) = (0, 0);
    let sb = p.trav.slot_bits();
    while done < rays.len() {
        let values = rays.get(next).map(|r| ray_inputs(next as u64, &r.ray));
        for (s, v) in ins.iter().zip(values.as_deref().unwrap_or(&vec![0; ins.len()])) {
            sim.set(*s, *v);
        }
        sim.eval();
        if values.is_some() && sim.get(ready) == 1 {
            next += 1;
        }
        if sim.get(accept) == 1 {
            in_slot[sim.get(slot_out) as usize] = sim.get(accept_id) as usize;
        }
        sim.tick();
        for &(u, kind, v, s, node) in &visit {
            if sim.get(v) == 1 {
                seen[kind] += 1;
                let slot = ((u as i128) << sb | sim.get(s)) as usize;
                walks[in_slot[slot]].push(sim.get(node) as u32);
            }
        }
        if sim.get(res_valid) == 1 {
            assert!(sim.get(res_id) < next as i128);
            done += 1;
        }
        assert!(sim.cycles < 2_000_000, "{label}: the core stopped");
    }
    for (k, r) in rays.iter().enumerate() {
        let mut want = Visits(Culled(Closest::new(&g, scene, &r.ray)), Vec::new());
        g.walk(scene, &r.ray, &mut want);
        assert_eq!(walks[k], want.1, "{label} at {mhz} MHz, {slots}×{units} slots, ray {k} (pixel {})", r.pixel);
    }
    seen
}

/// A spread core's unit sends a leaf with entries entered as the near child from its
/// parent's step, without a node step of its own (DECISIONS 137): over a frame the leaves
/// sent are the golden walk's near leaves, and the visits in N are all the other nodes.
#[test]
fn a_spread_cores_units_send_the_near_leaves_from_the_parents_step() {
    let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &Params::default()).unwrap();
    let rays = frame_rays(&scene, &Camera::default_for(&scene, 16, 16));
    let [in_n, sent] =
        assert_walks_are_the_culled_golden_walks("teapot", &scene, &rays, 150, 16, [4, 2], Piece::Mult18);
    let g = Golden::new(&scene);
    let (mut nodes, mut near_leaves) = (0u64, 0u64);
    for r in &rays {
        let (_, s) = g.trace_culled(&scene, &r.ray);
        (nodes, near_leaves) = (nodes + s.nodes as u64, near_leaves + s.near_leaves as u64);
    }
    assert!(near_leaves > 0);
    assert_eq!((in_n, sent), (nodes - near_leaves, near_leaves));
}

/// Every ray of a small frame through the whole core, many at once: each ray's node visits
/// are those of `Golden::trace_culled`, in its order — at three clock targets, with few
/// slots (rays wait for slots, slots park and are reused), one slot, and several units; and
/// with the products cut for the DSP48E (plane products and, at m = 20, the pipeline's).
#[test]
fn every_ray_visits_what_the_culled_golden_walk_visits_in_its_order() {
    let cornell = Params { n: 20, m: 20, ..Params::default() };
    let dsp48 = [
        ("teapot", Params::default(), 150, 32, [2, 1]),
        ("cornell", cornell, 250, 5, [3, 1]),
        ("cornell", cornell, 100, 3, [4, 2]),
    ];
    for (name, params, mhz, slots, units) in dsp48 {
        let scene = Scene::load(&SceneSource::Builtin(name.into()), &params).unwrap();
        let rays = frame_rays(&scene, &Camera::default_for(&scene, 20, 20));
        assert_walks_are_the_culled_golden_walks(name, &scene, &rays, mhz, slots, units, Piece::Dsp48);
    }
    for (name, params, mhz, slots, units) in [
        ("teapot", Params::default(), 150, 32, [2, 1]),
        ("cornell", cornell, 75, 3, [1, 1]),
        ("cornell", cornell, 250, 5, [3, 1]),
        ("teapot", Params::default(), 200, 2, [4, 1]),
        ("cornell", cornell, 150, 1, [2, 1]),
        // Several intersection pipelines: each lane's leaves in its own stream.
        ("teapot", Params::default(), 150, 16, [2, 2]),
        ("cornell", cornell, 100, 3, [4, 4]),
        ("teapot", Params::default(), 250, 5, [4, 2]),
        ("cornell", cornell, 150, 2, [8, 2]),
    ] {
        let scene = Scene::load(&SceneSource::Builtin(name.into()), &params).unwrap();
        let rays = frame_rays(&scene, &Camera::default_for(&scene, 20, 20));
        assert_walks_are_the_culled_golden_walks(name, &scene, &rays, mhz, slots, units, Piece::Mult18);
    }
}

/// Eight units visit up to eight nodes in a clock: the observation ports' sums (which `fxrt
/// sim` checks against the golden walk) must hold eight, not the four units' 3 bits.
#[test]
fn eight_units_count_every_node_step_and_triangle_test() {
    let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &Params::default()).unwrap();
    let roms = SceneRoms::of(&scene);
    let p = CoreParams::shaped(
        &roms,
        &crate::cores::top::CoreSpec { id_width: 16, slots: 16, units: 8, pipelines: 2, ..Default::default() },
    );
    p.check().unwrap();
    let rays = frame_rays(&scene, &Camera::default_for(&scene, 24, 24));
    let (results, stats) = simulate_rust(&p, &roms, &rays, &Stalls::none(), &|_| {});
    assert_eq!(mismatches(&scene, &rays, &results), 0);
    let (steps, tests) = crate::verify::frame::golden_walk(&scene, &rays);
    assert_eq!((stats.visits + stats.culls, stats.busy_cycles), (steps, tests));
}

/// Issue 27's small-width disagreement, reduced to two rays: the teapot at n = 4, m = 8,
/// pixels 0 and 1 of the default 8×8 view, one unit of two slots. Ray 1 enters node 50
/// at tmin = 8 with d0 = 8 (the near child's end equal to tmin, common on a 4-bit grid);
/// the near child was skipped when the sign of the ray's direction, which chooses the
/// decision limits (d0 ≥ tmin is d0 > tmin − 1), was taken from the token a clock ahead
/// of it in the ring instead of its own.
#[test]
fn each_token_decides_its_step_with_its_own_direction_sign() {
    let params = Params { n: 4, m: 8, ..Params::default() };
    let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &params).unwrap();
    let rays = frame_rays(&scene, &Camera::default_for(&scene, 8, 8));
    assert_eq!((rays[0].pixel, rays[1].pixel), (0, 1));
    assert_walks_are_the_culled_golden_walks("teapot n4 m8", &scene, &rays[..2], 150, 2, [1, 1], Piece::Mult18);
}

#[test]
fn the_core_with_its_generator_renders_the_golden_frame() {
    let (scene, cam) = inside_cornell();
    let g = Golden::new(&scene);
    let rg = RayGen::new(&scene, &cam).unwrap();
    let roms = SceneRoms::of(&scene);
    let p = CoreParams::new(&roms, 8, 1, crate::cores::clock::DEFAULT_TARGET_MHZ);
    let rays: Vec<PixelRay> = (0..cam.width * cam.height)
        .map(|i| PixelRay { pixel: i, ray: rg.ray(&g, i % cam.width, i / cam.width) })
        .collect();
    let (results, stats) = collect_batched(
        &core_with_raygen(&p, &std::rc::Rc::new(core_module(&p, &roms)), &rg),
        rays.len(),
        p.slot_count(),
        0,
        &|_| {},
    );
    assert_eq!(mismatches(&scene, &rays, &results), 0);
    assert!(results.iter().all(|r| r.1.is_some()), "every ray from inside the box hits a wall");
    assert!(stats.busy_cycles > 0);
}
