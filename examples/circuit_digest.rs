//! Circuit digest: every module of the default core and the throughput build, with the
//! layout-only facts (blocks) removed; SHA-256 of their Debug text.
use fxrt::cores::top::{CoreParams, core_module_with};
use fxrt::params::Params;
use fxrt::rtl::Module;
use fxrt::scene::images::SceneRoms;
use fxrt::scene::{Scene, SceneSource};
use sha2::{Digest, Sha256};

fn strip(m: &Module) -> Module {
    let mut m = m.clone();
    m.blocks.clear();
    m.current_block = None;
    for s in &mut m.signals {
        s.block = None;
    }
    for i in &mut m.instances {
        i.module = std::rc::Rc::new(strip(&i.module));
    }
    m
}

fn digest(m: &Module) -> String {
    let mut h = Sha256::new();
    h.update(format!("{:?}", strip(m)).as_bytes());
    format!("{:x}", h.finalize())
}

fn main() {
    for (label, leaf, slots, units, debug, m) in [
        ("default", None, None, None, false, None),
        ("default+debug", None, None, None, true, None),
        ("throughput 4x32 leaf 3", Some(3), Some(32), Some(4), false, None),
        ("1x16 debug", None, Some(16), Some(1), true, None),
        ("3x8 debug", None, Some(8), Some(3), true, None),
        ("2x8 m48 debug", None, Some(8), Some(2), true, Some(48)),
    ] {
        let mut params = Params::default();
        if let Some(m) = m {
            params.m = m;
        }
        if let Some(l) = leaf {
            params.leaf_size = l;
        }
        let scene = Scene::load(&SceneSource::Builtin("teapot".into()), &params).unwrap();
        let roms = SceneRoms::of(&scene);
        let p = match (slots, units) {
            (Some(s), Some(u)) => CoreParams::shaped(
                &roms,
                &fxrt::cores::top::CoreSpec {
                    id_width: 20,
                    div_bits: 1,
                    target_mhz: 150,
                    slots: s,
                    units: u,
                    pipelines: 1,
                    piece: Default::default(),
                },
            ),
            _ => CoreParams::new(&roms, 20, 1, 150),
        };
        let m = core_module_with(&p, &roms, debug);
        println!("{label}: {}", digest(&m));
        for sub in m.hierarchy() {
            println!("  {} {}", sub.name, &digest(&sub)[..16]);
        }
    }
}
