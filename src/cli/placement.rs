//! Where a core keeps its scene (`--memory`), and the files an external-memory core needs
//! beside it: shared by `gen`, `sim`, `synth` (`run.rs`) and `demo`.

use super::args::MemoryPlace;
use crate::error::Result;
use crate::io::OutputSet;
use crate::scene;
use crate::scene::images::SceneRoms;

/// For an external-memory core `p`: the image to put in memory at mem_base (`OUT/scene.bin`) and
/// its C header (`OUT/fxrt_scene.h`); nothing for an on-chip core.
pub fn add_scene_image(
    files: &mut OutputSet,
    out: &std::path::Path,
    p: &crate::cores::top::CoreParams,
    roms: &SceneRoms,
) -> Result<()> {
    if let Some(m) = &p.mem {
        let image = scene::memory::SceneImage::build(roms, m.spec.shape)?;
        files.add(&out.join("scene.bin"), &image.bytes)?;
        files.add(&out.join("fxrt_scene.h"), scene::memory_c::c_header(&roms.name, &image.layout).as_bytes())?;
    }
    Ok(())
}

/// The on-chip core `p`, or with `--memory external` (or `auto` when `p`'s ROMs and stacks do
/// not fit `bram_kbits`) the same shape with its scene in external memory; its block RAM then
/// checked against `bram_kbits`. Unless `--device` fitted the shape: a fitted core holds its
/// scene on chip by the device's own counts (the fit's: DP16KD on the LFE5U-85F, where the bit
/// count over-states a core of four units), so it is neither moved nor counted again.
pub fn place_checked(
    place: MemoryPlace,
    spec: crate::cores::memory_params::MemorySpec,
    bram_kbits: u64,
    roms: &SceneRoms,
    shape: &crate::cores::top::CoreSpec,
    p: crate::cores::top::CoreParams,
    fitted: bool,
) -> Result<crate::cores::top::CoreParams> {
    if fitted {
        return Ok(p);
    }
    let external = match place {
        MemoryPlace::Onchip => false,
        MemoryPlace::External => true,
        MemoryPlace::Auto => match p.check_device(roms, bram_kbits) {
            Ok(()) => false,
            // Several pipelines need the scene on chip (`check_pipelines`): say what does not
            // fit, not that the external core the user never asked for has one pipeline.
            Err(e) if shape.pipelines > 1 => return Err(e),
            Err(_) => true,
        },
    };
    let p = if external { crate::cores::top::CoreParams::external(roms, shape, spec)? } else { p };
    p.check_device(roms, bram_kbits)?;
    Ok(p)
}
