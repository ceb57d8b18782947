//! `fxrt gen --board`: the board design's files, and for the ULX3S its bitstream.

use super::config::{BoardConfig, GenConfig, GenScene};
use crate::board::{BoardDesign, pnr};
use crate::cores::top::CoreParams;
use crate::error::{Error, Result};
use crate::fpga::ecp5::Tools;
use crate::io::OutputSet;
use crate::model::camera::{Camera, CameraSpec};
use crate::scene::Scene;
use crate::scene::images::SceneRoms;
use std::path::PathBuf;

/// The board's camera: the options given, the eye inside the box unless --eye says where.
fn board_camera(scene: &Scene, spec: &CameraSpec) -> Result<crate::model::raygen::RayGen> {
    let spec = match spec.eye {
        Some(_) => spec.clone(),
        None => {
            let inside = Camera::inside(scene, spec.width, spec.height, spec.fov);
            CameraSpec { eye: Some(inside.eye), at: Some(spec.at.unwrap_or(inside.at)), ..spec.clone() }
        }
    };
    crate::model::raygen::RayGen::for_camera(scene, &spec)
}

/// The core's shape options for board `b`: as given, but with none given (and the scene on
/// chip) the ML509's core is fitted to its XC5VLX110T (DECISIONS 124; with its products cut
/// for the DSP48E that is two units, 60 of its 64, DECISIONS 131). The ULX3S's LFE5U-85F
/// holds the default core.
fn board_threads(c: &GenConfig, b: &BoardConfig) -> super::ThreadArgs {
    let on_chip = c.memory != super::args::MemoryPlace::External;
    match b.board {
        crate::board::Board::Ml509 if on_chip && c.threads.shape_is_default() => {
            super::ThreadArgs { device: Some(b.board.device()), ..c.threads }
        }
        _ => c.threads,
    }
}

/// Writes the board design; for the ULX3S (unless --no-bitstream) places, routes and packs it.
/// False when the bitstream misses its clock.
pub fn gen_board(c: &GenConfig, b: &BoardConfig) -> Result<bool> {
    let GenScene::Scene { source, params, search, raygen: Some(spec) } = &c.scene else {
        return Err(Error::param("board", "needs the scene itself (an OBJ or --builtin) and a camera"));
    };
    let mut scene = Scene::load(source, params)?;
    let g = board_camera(&scene, spec)?;
    super::config::ids_fit(c.ray_id_width, g.width, g.height)?;
    let external = c.memory == super::args::MemoryPlace::External;
    // The board's part cuts the products for its multipliers, with a shape given too.
    let base = crate::cores::top::CoreSpec { piece: c.threads.piece_or(b.board.device().piece()), ..c.core_spec() };
    let (spec, fit) = super::device::shape(&board_threads(c, b), Some(&mut scene), *search, base, external)?;
    let roms = SceneRoms::of(&scene);
    let p = CoreParams::shaped(&roms, &spec);
    p.check()?;
    if fit.is_none() {
        // A fitted shape holds its scene by the device's own counts (`place_checked`).
        p.check_device(&roms, c.bram_kbits)?;
    }
    let tools = if b.bitstream {
        Some(Tools::require().map_err(|e| Error::param("board", format!("{} (or --no-bitstream)", e.message)))?)
    } else {
        None
    };
    super::device::say(fit.as_ref());
    let mut d = BoardDesign::new(b.board, &p, &roms, &scene, &g, b.mhz, b.led_shift, None)?;
    d.device_fit = fit.as_ref().map(|f| serde_json::to_value(f).expect("a fit serialises"));
    let design: Vec<(PathBuf, String)> =
        d.files(c.vhdl, c.verilog).into_iter().map(|(n, t)| (c.out.join(n), t)).collect();
    let written = format!(
        "{} ({}, {} MHz from the {} MHz oscillator; frame {}x{}, golden checksum {:08x}) written to {}",
        d.top,
        d.board.title(),
        d.clock.mhz,
        d.board.osc_mhz(),
        g.width,
        g.height,
        d.check.golden,
        c.out.display()
    );
    let Some(tools) = tools else {
        let mut files = OutputSet::new();
        files.extend(design)?;
        files.commit()?;
        println!("{written}");
        return Ok(true);
    };
    // The design's files are written with the bitstream or not at all, after minutes of place
    // and route (held in memory meanwhile, so an interrupted run leaves none; a path that
    // cannot take them is refused first). The tools' folder keeps their logs either way: a
    // failure names them.
    design.iter().try_for_each(|(p, _)| crate::io::check_writable(p))?;
    let dir = c.out.join("pnr");
    eprintln!("placing and routing {} (minutes; logs in {})", d.top, dir.display());
    let timing = pnr::bitstream(&tools, &d, b.seed, &dir)?;
    let bit = std::fs::read(dir.join(&timing.bitstream))
        .map_err(|e| Error::file(&dir.join(&timing.bitstream), e.to_string()))?;
    let report = serde_json::to_string_pretty(&timing).unwrap_or_default() + "\n";
    let mut files = OutputSet::new();
    files.extend(design)?;
    files.add(&c.out.join(&timing.bitstream), &bit)?;
    files.add(&c.out.join(format!("{}_timing.json", d.top)), report.as_bytes())?;
    files.commit()?;
    println!("{written}");
    println!(
        "{}: {} MHz reached on the {} MHz board clock ({}), {} LUT4, {} FF, {} MULT18X18D, {} DP16KD; seed {}",
        timing.bitstream,
        timing.fmax_mhz,
        timing.clock_mhz,
        if timing.met { "met" } else { "NOT met" },
        timing.lut4,
        timing.ff,
        timing.mult18,
        timing.dp16kd,
        timing.seed
    );
    Ok(timing.met)
}
