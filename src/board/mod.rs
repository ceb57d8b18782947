//! `fxrt gen --board`: the board tops (docs/BOARDS.md). The logic — ray generator, core,
//! checksum, LEDs — is `cores::board`, printed like every core; the top around it is
//! boilerplate rendered from `hdl/board_top.{v,vhd}`: the PLL, the reset synchroniser and the
//! pins, constrained by `hdl/ulx3s.lpf` or `hdl/ml509.ucf`.

pub mod pll;
pub mod pnr;
pub mod sim;

use crate::cores::board::{BoardCheck, LED_FRAME_BITS, board_logic, result_widths};
use crate::cores::top::{CoreParams, core_module_with};
use crate::error::{Error, Result};
use crate::model::checksum::frame_checksum;
use crate::model::raygen::RayGen;
use crate::render::fast::FastGolden;
use crate::rtl::{Module, emit};
use crate::scene::Scene;
use crate::scene::images::SceneRoms;
use askama::Template;
use pll::{Ecp5Pll, V5Pll};
use serde_json::json;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Board {
    /// Radiona ULX3S: LFE5U-85F, 25 MHz oscillator; nextpnr and ecppack make the bitstream.
    Ulx3s,
    /// Xilinx ML509 / XUPV5-LX110T: XC5VLX110T-1FF1136, 100 MHz oscillator; an ISE project.
    Ml509,
}

/// LED sites and I/O standards, LED 0 first: ULX3S from ulx3s_v20.lpf, ML509 (GPIO_LED_0..7:
/// banks 3 at 2.5 V and 21 at 1.8 V) from the board's UCF as copied in VLSI-EDA/PoC and
/// hdl4fpga (docs/BOARDS.md).
const ULX3S_LEDS: [(&str, &str); 8] = [
    ("B2", "LVCMOS33"),
    ("C2", "LVCMOS33"),
    ("C1", "LVCMOS33"),
    ("D2", "LVCMOS33"),
    ("D1", "LVCMOS33"),
    ("E2", "LVCMOS33"),
    ("E1", "LVCMOS33"),
    ("H3", "LVCMOS33"),
];
const ML509_LEDS: [(&str, &str); 8] = [
    ("H18", "LVCMOS25"),
    ("L18", "LVCMOS25"),
    ("G15", "LVCMOS25"),
    ("AD26", "LVCMOS18"),
    ("G16", "LVCMOS25"),
    ("AD25", "LVCMOS18"),
    ("AD24", "LVCMOS18"),
    ("AE24", "LVCMOS18"),
];

impl Board {
    pub fn name(self) -> &'static str {
        match self {
            Board::Ulx3s => "ulx3s",
            Board::Ml509 => "ml509",
        }
    }

    pub fn title(self) -> &'static str {
        match self {
            Board::Ulx3s => "ULX3S (LFE5U-85F)",
            Board::Ml509 => "ML509 (XC5VLX110T-1FF1136)",
        }
    }

    pub fn osc_mhz(self) -> f64 {
        match self {
            Board::Ulx3s => 25.0,
            Board::Ml509 => 100.0,
        }
    }

    /// The board's FPGA.
    pub fn device(self) -> crate::fpga::device::Device {
        match self {
            Board::Ulx3s => crate::fpga::device::Device::Lfe5u85f,
            Board::Ml509 => crate::fpga::device::Device::Xc5vlx110t,
        }
    }

    /// DSP48E slices on the XC5VLX110T: the core must fit (`cores::cost::dsp48e_estimate`).
    /// The ULX3S's 156 MULT18X18D hold two traversal units (70 measured) and nextpnr says so
    /// when a design does not fit.
    pub fn dsp48e(self) -> Option<u32> {
        match self {
            Board::Ulx3s => None,
            Board::Ml509 => Some(crate::fpga::device::Device::Xc5vlx110t.capacity().multipliers),
        }
    }
}

/// The PLL setting for a board clock: (multiplier, input divider, output divider, ECP5 phase).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoardClock {
    pub mhz: f64,
    pub mult: u32,
    pub div_in: u32,
    pub div_out: u32,
    pub cphase: u32,
}

impl BoardClock {
    pub fn for_board(board: Board, target_mhz: f64) -> Result<BoardClock> {
        let osc = board.osc_mhz();
        let none = || {
            Error::param(
                "board-mhz",
                format!("{target_mhz} MHz: the {} PLL cannot make it from {osc} MHz", board.name()),
            )
        };
        Ok(match board {
            Board::Ulx3s => {
                let p = Ecp5Pll::for_clock(osc, target_mhz).ok_or_else(none)?;
                BoardClock {
                    mhz: p.out_mhz(osc),
                    mult: p.clkfb_div,
                    div_in: p.clki_div,
                    div_out: p.clkop_div,
                    cphase: p.cphase(),
                }
            }
            Board::Ml509 => {
                let p = V5Pll::for_clock(osc, target_mhz).ok_or_else(none)?;
                BoardClock {
                    mhz: p.out_mhz(osc),
                    mult: p.clkfbout_mult,
                    div_in: p.divclk_divide,
                    div_out: p.clkout0_divide,
                    cphase: 0,
                }
            }
        })
    }
}

/// The frame counter bit to show on LED 2: the lowest whose LED changes no faster than about
/// four times a second, for a frame of `pixels` rays at `clock_mhz`, a ray at most every
/// `ray_cycles` clocks (the generator's bound; the core is slower, so the LED is too).
pub fn led_shift(pixels: u64, ray_cycles: u32, clock_mhz: f64) -> u32 {
    let frame_s = pixels as f64 * ray_cycles as f64 / (clock_mhz * 1e6);
    let mut shift = 0;
    while frame_s * ((1u64 << shift) as f64) < 0.125 && shift < 40 {
        shift += 1;
    }
    shift
}

/// Clocks per ray the ray generator gives at most (its divider sets take turns: a ray every
/// `CLOCKS_PER_RAY` clocks or faster, whatever m and C).
pub fn generator_cycles(_p: &CoreParams) -> u32 {
    crate::cores::raygen::CLOCKS_PER_RAY
}

/// A board design: the logic module, its top's name and everything the files say.
pub struct BoardDesign {
    pub board: Board,
    pub clock: BoardClock,
    pub logic: Module,
    pub top: String,
    pub check: BoardCheck,
    pub pixels: u64,
    pub scene: String,
    /// The core's shape in the manifest: slots, units, pipelines, leaf size, stack, the
    /// multiplier cut.
    pub core: serde_json::Value,
    /// The fit that chose the shape (`--device`, or the ML509 with no shape given).
    pub device_fit: Option<serde_json::Value>,
}

/// The golden model's checksum of the frame `g` generates.
pub fn golden_checksum(scene: &Scene, core: &Module, g: &RayGen) -> u32 {
    let fast = FastGolden::new(scene);
    let w = result_widths(core);
    let pixels = g.width as u64 * g.height as u64;
    let ray = |i: u64| g.ray(&fast.golden, (i % g.width as u64) as u32, (i / g.width as u64) as u32);
    frame_checksum(&w, (0..pixels).map(|i| (i, fast.trace(&ray(i)).0)))
}

impl BoardDesign {
    /// The design for `board` at `clock_mhz` (the PLL's nearest clock not above it); the LED
    /// frame bit `led_shift`, or one chosen for the eye; the golden checksum `golden`, or the
    /// golden model's.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        board: Board,
        p: &CoreParams,
        roms: &SceneRoms,
        scene: &Scene,
        g: &RayGen,
        clock_mhz: f64,
        led_shift_bit: Option<u32>,
        golden: Option<u32>,
    ) -> Result<BoardDesign> {
        let clock = BoardClock::for_board(board, clock_mhz)?;
        let pixels = g.width as u64 * g.height as u64;
        let golden = golden.unwrap_or_else(|| golden_checksum(scene, &core_module_with(p, roms, false), g));
        let shift = led_shift_bit.unwrap_or_else(|| led_shift(pixels, generator_cycles(p), clock.mhz));
        let check = BoardCheck { golden, led_shift: shift };
        let mut logic = board_logic(p, roms, g, check, false);
        logic.std_ports = true;
        let dsp = crate::cores::cost::dsp48e_estimate(&logic);
        if let Some(have) = board.dsp48e().filter(|&have| dsp > have) {
            return Err(Error::param(
                "units",
                format!(
                    "the core needs {dsp} DSP48E, the {}'s XC5VLX110T has {have}: use fewer --units or --pipelines",
                    board.name()
                ),
            ));
        }
        let top = format!("fxrt_{}{}", board.name(), logic.name.trim_start_matches("fxrt_board"));
        let core = json!({
            "ray_slots_per_unit": p.trav.slots, "traversal_units": p.units, "intersection_pipelines": p.pipelines,
            "leaf_size": roms.params.leaf_size, "stack_depth": p.trav.stack_depth,
            "multiplier_pieces": p.trav.product.piece.label(),
        });
        let scene = roms.name.clone();
        Ok(BoardDesign { board, clock, logic, top, check, pixels, scene, core, device_fit: None })
    }

    fn template(&self) -> TopTemplate<'_> {
        let leds = match self.board {
            Board::Ulx3s => ULX3S_LEDS,
            Board::Ml509 => ML509_LEDS,
        };
        TopTemplate {
            top: &self.top,
            logic: &self.logic.name,
            scene: &self.scene,
            title: self.board.title(),
            board: self.board.name(),
            osc_mhz: format!("{}", self.board.osc_mhz()),
            osc_period_ns: format!("{:.3}", 1000.0 / self.board.osc_mhz()),
            clock_mhz: format!("{}", (self.clock.mhz * 1e6).round() / 1e6),
            clock_period_ns: format!("{:.3}", 1000.0 / self.clock.mhz),
            mult: self.clock.mult,
            div_in: self.clock.div_in,
            div_out: self.clock.div_out,
            cphase: self.clock.cphase,
            leds: leds.iter().enumerate().map(|(k, s)| (k, s.0, s.1)).collect(),
        }
    }

    /// The top's HDL in `ext` ("v" or "vhd").
    pub fn top_hdl(&self, ext: &str) -> String {
        let t = self.template();
        let text = if ext == "v" { TopVerilog(&t).render() } else { TopVhdl(&t).render() };
        text.expect("board top template renders") + "\n"
    }

    /// The pin and clock constraints: (`<top>.lpf` or `<top>.ucf`, text).
    pub fn constraints(&self) -> (String, String) {
        let t = self.template();
        match self.board {
            Board::Ulx3s => (format!("{}.lpf", self.top), Lpf(&t).render().expect("LPF renders") + "\n"),
            Board::Ml509 => (format!("{}.ucf", self.top), Ucf(&t).render().expect("UCF renders") + "\n"),
        }
    }

    /// Every file: the logic's HDL and the top in the languages asked for, the constraints, the
    /// ISE project (ML509), the manifest.
    pub fn files(&self, vhdl: bool, verilog: bool) -> Vec<(String, String)> {
        let mut out: Vec<(String, String)> = Vec::new();
        for (ext, on) in [("vhd", vhdl), ("v", verilog)] {
            if on {
                out.extend(emit::design_files(&self.logic, ext));
                out.push((format!("{}.{ext}", self.top), self.top_hdl(ext)));
            }
        }
        out.push(self.constraints());
        // The ML509's bitstream comes from ISE: its project script.
        if self.board == Board::Ml509 {
            let (language, ext) = if vhdl { ("VHDL", "vhd") } else { ("Verilog", "v") };
            let mut files: Vec<String> = self.logic.hierarchy().iter().map(|x| format!("{}.{ext}", x.name)).collect();
            files.push(format!("{}.{ext}", self.top));
            let tcl = crate::generate::ise_project(&self.top, &self.scene, language, &files, true);
            out.push((format!("{}.tcl", self.top), tcl));
        }
        let names: Vec<String> = out.iter().map(|f| f.0.clone()).collect();
        out.push((
            format!("{}.json", self.top),
            serde_json::to_string_pretty(&self.manifest(&names)).unwrap_or_default() + "\n",
        ));
        out
    }

    fn manifest(&self, files: &[String]) -> serde_json::Value {
        json!({
            "name": self.top,
            "generator": format!("fxrt {}", env!("CARGO_PKG_VERSION")),
            "board": self.board.name(),
            "part": match self.board { Board::Ulx3s => "LFE5U-85F-6BG381C", Board::Ml509 => "XC5VLX110T-1FF1136" },
            "logic": self.logic.name,
            "scene": self.scene,
            "clock": {
                "oscillator_mhz": self.board.osc_mhz(),
                "pll": { "multiplier": self.clock.mult, "input_divider": self.clock.div_in, "output_divider": self.clock.div_out },
                "clock_mhz": self.clock.mhz,
            },
            "frame_rays": self.pixels,
            "golden_checksum": format!("{:08x}", self.check.golden),
            "leds": {
                "0": "the last frame's checksum equals the golden model's",
                "1": "some frame's checksum did not (held until reset)",
                "7..2": format!("frame counter bits {}..{}", self.check.led_shift + LED_FRAME_BITS - 1, self.check.led_shift),
            },
            "reset": "the button (and the PLL not locked), through a three-flip-flop synchroniser",
            "core": self.core,
            "device_fit": self.device_fit,
            "files": files,
        })
    }
}

#[derive(Clone)]
struct TopTemplate<'a> {
    top: &'a str,
    logic: &'a str,
    scene: &'a str,
    title: &'a str,
    board: &'a str,
    osc_mhz: String,
    osc_period_ns: String,
    clock_mhz: String,
    clock_period_ns: String,
    mult: u32,
    div_in: u32,
    div_out: u32,
    cphase: u32,
    /// (LED, site, I/O standard).
    leds: Vec<(usize, &'static str, &'static str)>,
}

/// A template over a borrowed set of fields (`$fields<'a>`): several templates share one.
macro_rules! board_template {
    ($name:ident, $fields:ident, $path:literal) => {
        #[derive(askama::Template)]
        #[template(path = $path, escape = "none")]
        struct $name<'a, 'b>(&'b $fields<'a>);
        impl<'a, 'b> std::ops::Deref for $name<'a, 'b> {
            type Target = $fields<'a>;
            fn deref(&self) -> &$fields<'a> {
                self.0
            }
        }
    };
}
pub(crate) use board_template;
board_template!(TopVerilog, TopTemplate, "board_top.v");
board_template!(TopVhdl, TopTemplate, "board_top.vhd");
board_template!(Lpf, TopTemplate, "ulx3s.lpf");
board_template!(Ucf, TopTemplate, "ml509.ucf");
