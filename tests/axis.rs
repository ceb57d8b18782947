//! The AXI4-Stream layout's host side: the byte layout of the default build (docs/AXIS.md),
//! Rust's pack and unpack, and the generated C header doing the same, byte for byte.

mod common;

use fxrt::cores::axis::{Field, Layout};
use fxrt::cores::top::{CoreParams, core_module};
use fxrt::generate::axis_host::{c_header, pack_ray, pack_result, unpack_result};
use fxrt::model::camera::Camera;
use fxrt::model::golden::{GridRay, Hit};
use fxrt::params::Params;
use fxrt::render::fast::FastGolden;
use fxrt::rng::SplitMix64;
use fxrt::scene::images::SceneRoms;
use fxrt::scene::{Scene, SceneSource};
use fxrt::verify::frame::frame_rays;

fn build(name: &str, params: Params) -> (Scene, CoreParams, Layout, String) {
    let scene = Scene::load(&SceneSource::Builtin(name.into()), &params).unwrap();
    let roms = SceneRoms::of(&scene);
    let p = CoreParams::new(&roms, 20, 1, fxrt::cores::clock::DEFAULT_TARGET_MHZ);
    let core = core_module(&p, &roms);
    let layout = Layout::of(&core);
    (scene, p, layout, format!("{}_axis", core.name))
}

/// The default build's layout, as docs/AXIS.md gives it.
#[test]
fn the_default_layout_is_the_documented_one() {
    let (_, _, l, _) = build("teapot", Params::default());
    let row = |f: &Field| (f.name, f.offset, f.bytes, f.bits, f.signed);
    let ray: Vec<_> = l.ray.iter().map(row).collect();
    assert_eq!(
        ray,
        [
            ("id", 0, 3, 20, false),
            ("ox", 3, 4, 29, false),
            ("oy", 7, 4, 29, false),
            ("oz", 11, 4, 29, false),
            ("wx", 15, 4, 32, true),
            ("wy", 19, 4, 32, true),
            ("wz", 23, 4, 32, true),
            ("invx", 27, 6, 48, true),
            ("invy", 33, 6, 48, true),
            ("invz", 39, 6, 48, true),
        ]
    );
    let res: Vec<_> = l.res.iter().map(row).collect();
    assert_eq!(
        res,
        [
            ("id", 0, 3, 20, false),
            ("flags", 3, 1, 8, false),
            ("tri", 4, 2, 13, false),
            ("t", 6, 4, 30, false),
            ("u", 10, 4, 32, false),
            ("v", 14, 4, 32, false),
        ]
    );
    assert_eq!((l.ray_bytes, l.res_bytes), (64, 32));
}

/// Little-endian, sign-extended, padding zero; unpack(pack(x)) = x for a frame's results.
#[test]
fn rust_packs_little_endian_and_unpacks_what_it_packed() {
    let (scene, _, l, _) = build("cornell", Params::default());
    let ray = GridRay { o: [0x0102_0304, 5, 6], w: [-2, 7, -(1 << 30)], inv: [-3, 1 << 40, 9] };
    let b = pack_ray(&l, 0xABCDE, &ray);
    assert_eq!(b.len(), 64);
    assert_eq!(&b[0..3], &[0xDE, 0xBC, 0x0A], "id");
    assert_eq!(&b[3..7], &[0x04, 0x03, 0x02, 0x01], "ox");
    assert_eq!(&b[15..19], &[0xFE, 0xFF, 0xFF, 0xFF], "wx = -2");
    assert_eq!(&b[23..27], &[0x00, 0x00, 0x00, 0xC0], "wz = -2^30");
    assert_eq!(&b[27..33], &[0xFD, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF], "invx = -3");
    assert_eq!(&b[33..39], &[0, 0, 0, 0, 0, 1], "invy = 2^40");
    assert!(b[45..].iter().all(|&x| x == 0), "padding");
    let g = FastGolden::new(&scene);
    let rays = frame_rays(&scene, &Camera::default_for(&scene, 12, 12));
    let mut hits = 0;
    for r in &rays {
        let hit = g.trace(&r.ray).0;
        hits += hit.is_some() as u32;
        let bytes = pack_result(&l, r.pixel as u64, hit);
        assert_eq!(bytes.len(), l.res_bytes as usize);
        assert_eq!(unpack_result(&l, &bytes), (r.pixel as u64, hit));
    }
    assert!(hits > 20);
    let miss = pack_result(&l, 7, None);
    assert_eq!(miss[0], 7);
    assert!(miss[1..].iter().all(|&x| x == 0), "a miss is its id and zeros");
}

/// `cc`, or the compiler `CC` names, if it runs.
fn compiler() -> Option<String> {
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let ok = std::process::Command::new(&cc).arg("--version").output().is_ok_and(|o| o.status.success());
    ok.then_some(cc)
}

/// A C expression of value `v` for the header's integer type (`__int128` when `wide`).
fn c_int(v: i128, wide: bool, p: &str) -> String {
    if !wide {
        return format!("INT64_C({})", v as i64);
    }
    let (hi, lo) = ((v >> 64) as i64, v as u64);
    format!("(({p}_int)INT64_C({hi}) * (({p}_int)1 << 64) + ({p}_int)UINT64_C({lo}))")
}

#[test]
fn the_c_header_packs_and_unpacks_as_rust_does() {
    let Some(cc) = compiler() else {
        common::say("skipped: no C compiler (cc, or $CC) to test the generated C header with");
        return;
    };
    // The default widths (every signed field on whole bytes), widths with sign extension
    // inside the bytes (27-bit directions, 43-bit reciprocals), and 73-bit reciprocals
    // (__int128 in C).
    let sets = [
        Params::default(),
        Params { n: 23, m: 27, c: 16, ..Params::default() },
        Params { n: 20, m: 33, c: 40, ..Params::default() },
    ];
    for params in sets {
        let (scene, p, l, module) = build("cornell", params);
        let wide = l.ray.iter().any(|f| f.bits > 64);
        assert_eq!(wide, p.trav.inv_width() > 64);
        let mut rays: Vec<(u64, GridRay)> =
            frame_rays(&scene, &Camera::default_for(&scene, 5, 5)).iter().map(|r| (r.pixel as u64, r.ray)).collect();
        // The extremes of every field.
        let (n, f, iw) = (params.n, params.m - 1, p.trav.inv_width());
        let top = (1i64 << n) - 1;
        let w = (1i64 << f) - 1;
        let inv = (1i128 << (iw - 1)) - 1;
        rays.push(((1 << 20) - 1, GridRay { o: [top, 0, top], w: [w, -w, 0], inv: [inv, -inv - 1, -1] }));
        let mut rng = SplitMix64(9);
        let results: Vec<Vec<u8>> = (0..40)
            .map(|k| {
                let mut b: Vec<u8> = (0..l.res_bytes).map(|_| rng.next_u64() as u8).collect();
                b[3] = (b[3] & !1) | (k % 2) as u8; // hits and misses
                b
            })
            .collect();
        let mut prog =
            format!("#include \"{module}.h\"\n#include <stdio.h>\n#include <inttypes.h>\n\nint main(void)\n{{\n");
        prog += &format!("    static const {module}_ray rays[] = {{\n");
        for (id, r) in &rays {
            let v = |x: i128| c_int(x, wide, &module);
            let o: Vec<String> = r.o.iter().map(|&x| v(x as i128)).collect();
            let w: Vec<String> = r.w.iter().map(|&x| v(x as i128)).collect();
            let i: Vec<String> = r.inv.iter().map(|&x| v(x)).collect();
            prog += &format!(
                "        {{UINT64_C({id}), {{{}}}, {{{}}}, {{{}}}}},\n",
                o.join(", "),
                w.join(", "),
                i.join(", ")
            );
        }
        prog += "    };\n    static const uint8_t results[][";
        prog += &format!("{}] = {{\n", l.res_bytes);
        for b in &results {
            let bytes: Vec<String> = b.iter().map(|x| format!("{x}")).collect();
            prog += &format!("        {{{}}},\n", bytes.join(", "));
        }
        let up = module.to_uppercase();
        prog += &format!(
            "    }};\n    for (unsigned k = 0; k < sizeof rays / sizeof rays[0]; k++) {{\n\
             \x20       uint8_t t[{up}_RAY_BYTES];\n\
             \x20       {module}_pack_ray(t, &rays[k]);\n\
             \x20       for (unsigned i = 0; i < {up}_RAY_BYTES; i++)\n\
             \x20           printf(\"%02x\", t[i]);\n\
             \x20       printf(\"\\n\");\n    }}\n\
             \x20   for (unsigned k = 0; k < sizeof results / sizeof results[0]; k++) {{\n\
             \x20       {module}_result r;\n\
             \x20       {module}_unpack_result(results[k], &r);\n\
             \x20       if (r.hit)\n\
             \x20           printf(\"%\" PRIu64 \" %\" PRIu32 \" %\" PRId64 \" %\" PRId64 \" %\" PRId64 \"\\n\", r.id, r.tri, r.t, r.u, r.v);\n\
             \x20       else\n\
             \x20           printf(\"%\" PRIu64 \" miss\\n\", r.id);\n    }}\n    return 0;\n}}\n"
        );
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join(format!("{module}.h")), c_header(&module, &l)).unwrap();
        std::fs::write(dir.path().join("t.c"), &prog).unwrap();
        let exe = dir.path().join("t");
        let out = std::process::Command::new(&cc)
            .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O1", "-o"])
            .arg(&exe)
            .arg(dir.path().join("t.c"))
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let run = std::process::Command::new(&exe).output().unwrap();
        assert!(run.status.success());
        let text = String::from_utf8(run.stdout).unwrap();
        let mut want: Vec<String> = rays
            .iter()
            .map(|(id, r)| pack_ray(&l, *id, r).iter().map(|b| format!("{b:02x}")).collect::<String>())
            .collect();
        want.extend(results.iter().map(|b| match unpack_result(&l, b) {
            (id, Some(Hit { tri, t, u, v })) => format!("{id} {tri} {t} {u} {v}"),
            (id, None) => format!("{id} miss"),
        }));
        assert_eq!(text.lines().collect::<Vec<_>>(), want, "params {params:?}");
    }
}
