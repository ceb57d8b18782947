//! `--device`: the core's shape fitted to a device (`sweep::fit`), or the one given.

use super::args::ThreadArgs;
use crate::cores::top::CoreSpec;
use crate::error::{Error, Result};
use crate::scene::Scene;

/// `base` (ray ids, divider, clock target) with the slots, units and pipelines given, or with
/// `--device` those of the fit, which is said on stderr a shape a line.
pub fn shape(t: &ThreadArgs, scene: Option<&Scene>, base: CoreSpec) -> Result<CoreSpec> {
    let given = CoreSpec { slots: t.slots, units: t.units, pipelines: t.pipelines, ..base };
    let Some(device) = t.device else {
        return Ok(given);
    };
    let Some(scene) = scene else {
        return Err(Error::param("device", "needs the scene itself (an OBJ or --builtin), not a folder of ROM images"));
    };
    let bar = indicatif::ProgressBar::new_spinner();
    bar.set_message(format!("fitting the core to the {}: shapes run", device.name()));
    let fit = crate::sweep::fit::fit(device, scene, &base, &|| bar.inc(1))?;
    bar.finish_and_clear();
    let unit = if fit.device == "LFE5U-85F" { "" } else { " Kb" };
    for c in fit.candidates.iter().filter(|c| c.rays_per_clock.is_some()) {
        eprintln!(
            "device {}: {} units × {} slots, {} pipelines: {} of {} multipliers, {}{unit} of {}{unit} block RAM, \
             {:.4} rays per clock ({})",
            fit.device,
            c.units,
            c.slots,
            c.pipelines,
            c.multipliers,
            fit.multipliers_of,
            c.block_ram,
            fit.block_ram_of,
            c.rays_per_clock.unwrap_or(0.0),
            fit.frame
        );
    }
    let c = &fit.chosen;
    eprintln!("device {}: chosen {} units × {} slots, {} pipelines", fit.device, c.units, c.slots, c.pipelines);
    Ok(fit.spec(&base))
}
