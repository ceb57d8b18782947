//! `--device`: the core's shape fitted to a device (`sweep::fit`), or the one given.

use super::args::ThreadArgs;
use crate::cores::top::CoreSpec;
use crate::error::{Error, Result};
use crate::scene::Scene;
use crate::sweep::fit::{Fit, SceneSearch};

/// `base` (ray ids, divider, clock target) with the slots, units and pipelines given, or with
/// `--device` those of the fit (returned too: `say` tells it once the command has done its
/// work, so a later refusal stays one line). The fit may rebuild `scene` with another leaf
/// size or stack depth where `search` allows it: `scene` is then that build. The fit counts
/// cores with the scene on chip, so not with `external` memory.
pub fn shape(
    t: &ThreadArgs,
    scene: Option<&mut Scene>,
    search: SceneSearch,
    base: CoreSpec,
    external: bool,
) -> Result<(CoreSpec, Option<Fit>)> {
    // A device's core cuts its products for the device's multipliers, fitted or given, unless
    // --dsp says otherwise.
    let base = CoreSpec { piece: t.piece_or(base.piece), ..base };
    let given = CoreSpec { slots: t.slots, units: t.units, pipelines: t.pipelines, ..base };
    let Some(device) = t.device else {
        return Ok((given, None));
    };
    let Some(scene) = scene else {
        return Err(Error::param("device", "needs the scene itself (an OBJ or --builtin), not a folder of ROM images"));
    };
    let (fit, chosen) = fit_on_chip(device, scene, search, &base, external)?;
    *scene = chosen;
    Ok((fit.spec(&base), Some(fit)))
}

/// `sweep::fit` behind a spinner on stderr; refused (naming `--device`) for a core whose scene
/// is in `external` memory, as the fit counts cores with the scene on chip.
pub fn fit_on_chip(
    device: crate::fpga::device::Device,
    scene: &Scene,
    search: SceneSearch,
    base: &CoreSpec,
    external: bool,
) -> Result<(Fit, Scene)> {
    on_chip(external)?;
    let bar = indicatif::ProgressBar::new_spinner();
    bar.set_message(format!("fitting the core to the {}: shapes run", device.name()));
    let fitted = crate::sweep::fit::fit(device, scene, search, base, &|| bar.inc(1));
    bar.finish_and_clear();
    fitted
}

/// Refuses `--device` for a core whose scene is in `external` memory: the fit counts cores with
/// the scene on chip.
pub fn on_chip(external: bool) -> Result<()> {
    if external {
        return Err(Error::param("device", "fits cores with the scene on chip: not with --memory external (yet)"));
    }
    Ok(())
}

/// The fit's shapes and choice on stderr, a line each.
pub fn say(fit: Option<&Fit>) {
    for line in fit.map(Fit::lines).unwrap_or_default() {
        eprintln!("{line}");
    }
}
