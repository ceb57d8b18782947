//! What every sweep picture draws with: the compiled-in font (DejaVu Sans, so no system font
//! is needed), the plots' size, their legend, and plotters' errors as fxrt's.

use crate::error::{Error, Result};
use plotters::prelude::*;

/// The font family name plots and grids draw with.
pub const FONT: &str = "fxrt-sans";

pub fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // The font is compiled in and known to be valid.
        plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular())
            .unwrap_or_else(|_| panic!("the embedded DejaVu Sans is a valid font"));
    });
}

pub const W: u32 = 900;
pub const H: u32 = 560;

/// The sweep plots' legend: upper left, on a light box.
pub fn draw_legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
) -> Result<()> {
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .label_font((FONT, 14))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(plot_err)
}

pub fn plot_err(e: impl std::fmt::Display) -> Error {
    Error::new("sweep plot", e.to_string())
}
