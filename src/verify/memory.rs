//! The external memory every simulator puts behind the core's AXI4 read port (docs/MEMORY.md
//! "The memory model"): the scene image at address `base`, a burst's first beat `latency`
//! clocks after its address was taken, then one beat per clock, at most `outstanding` bursts
//! taken and not finished, served in order; optionally a random extra delay per burst and
//! random clocks without a beat, from a 32-bit xorshift that steps once per clock — so the
//! testbench models in VHDL and Verilog (`testbench`) give the same beats on the same clocks.
//!
//! Every output is a register (it changes only at a clock edge, from what was sampled there):
//! `arready`, `rvalid`, `rdata`, `rlast`. RVALID, once high, stays high until the beat is taken.

use std::collections::VecDeque;

/// How the memory answers (`--mem-latency` and the rest, docs/USAGE.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryTiming {
    /// Clocks from the address handshake to the first beat (≥ 1).
    pub latency: u32,
    /// Bursts taken and not finished, at most (≥ 1).
    pub outstanding: u32,
    /// A burst's first beat comes up to this many clocks later still (uniform, per burst).
    pub extra_delay: u32,
    /// Chance in 256 that a clock which could carry a new beat carries none.
    pub pause_in_256: u32,
    /// The xorshift's start (0 is taken as 1).
    pub seed: u32,
}

impl Default for MemoryTiming {
    fn default() -> Self {
        MemoryTiming {
            latency: DEFAULT_LATENCY,
            outstanding: DEFAULT_OUTSTANDING,
            extra_delay: 0,
            pause_in_256: 0,
            seed: 1,
        }
    }
}

pub const DEFAULT_LATENCY: u32 = 40;

/// The byte address the simulations put the scene image at (`mem_base`): not 0, so a core that
/// forgot the base reads the wrong bytes.
pub const SIM_BASE: u64 = 0x10_0000;
pub const DEFAULT_OUTSTANDING: u32 = 16;
/// The longest latency `--mem-latency` takes.
pub const MAX_LATENCY: u32 = 1000;

impl MemoryTiming {
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        if self.latency == 0 || self.latency > MAX_LATENCY {
            return Err(("mem-latency", format!("{} clocks: from 1 to {MAX_LATENCY}", self.latency)));
        }
        if self.outstanding == 0 || self.outstanding > 256 {
            return Err(("mem-outstanding", format!("{}: from 1 to 256 bursts", self.outstanding)));
        }
        if self.extra_delay > MAX_LATENCY {
            return Err(("mem-jitter", format!("{} clocks: at most {MAX_LATENCY}", self.extra_delay)));
        }
        if self.pause_in_256 > 255 {
            return Err(("mem-pauses", format!("{} in 256: at most 255", self.pause_in_256)));
        }
        Ok(())
    }
}

/// One step of the 32-bit xorshift (Marsaglia's 13, 17, 5), as the HDL models write it.
pub fn xorshift32(mut x: u32) -> u32 {
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    x
}

/// What the master drives in a clock.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MasterOut {
    pub arvalid: bool,
    pub araddr: u64,
    /// Beats − 1.
    pub arlen: u32,
    pub rready: bool,
}

/// What the memory drives in a clock (all registers).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct MemoryOut {
    pub arready: bool,
    pub rvalid: bool,
    /// Little-endian: byte k of the beat is bits 8k .. 8k + 7.
    pub rdata: u128,
    pub rlast: bool,
}

struct Burst {
    addr: u64,
    beats: u32,
    first_clock: u64,
}

pub struct MemoryModel {
    image: Vec<u8>,
    base: u64,
    beat_bytes: u32,
    timing: MemoryTiming,
    x: u32,
    clock: u64,
    bursts: VecDeque<Burst>,
    /// Beats of the front burst already taken.
    taken: u32,
    out: MemoryOut,
    /// Figures: beats carried, clocks with RVALID high, bursts taken.
    pub beats: u64,
    pub bursts_taken: u64,
}

impl MemoryModel {
    pub fn new(image: Vec<u8>, base: u64, mem_bits: u32, timing: MemoryTiming) -> MemoryModel {
        let out = MemoryOut { arready: true, ..MemoryOut::default() };
        let x = if timing.seed == 0 { 1 } else { timing.seed };
        MemoryModel {
            image,
            base,
            beat_bytes: mem_bits / 8,
            timing,
            x,
            clock: 0,
            bursts: VecDeque::new(),
            taken: 0,
            out,
            beats: 0,
            bursts_taken: 0,
        }
    }

    /// A clock of the one-clock reset (AXI's ARESETn): bursts in flight are forgotten; the
    /// xorshift and the clock count do not step.
    pub fn reset(&mut self) {
        self.bursts.clear();
        self.taken = 0;
        self.out.arready = true;
        self.out.rvalid = false;
        self.out.rlast = false;
    }

    /// The memory's outputs in this clock.
    pub fn out(&self) -> &MemoryOut {
        &self.out
    }

    /// The clock edge: takes what the master drove in the clock that ends and sets the
    /// outputs of the next one. Panics on a read outside the image (a core fault a test must
    /// see, never a user's input) or a burst the port does not make.
    pub fn clock(&mut self, m: &MasterOut) {
        self.x = xorshift32(self.x);
        if m.arvalid && self.out.arready {
            assert!(m.araddr >= self.base, "read below the scene image: {:#x}", m.araddr);
            let extra = if self.timing.extra_delay > 0 { (self.x >> 8) % (self.timing.extra_delay + 1) } else { 0 };
            let first_clock = self.clock + (self.timing.latency + extra) as u64;
            // In order: a burst's first beat never comes before the previous burst's.
            let first_clock = self.bursts.back().map_or(first_clock, |b| first_clock.max(b.first_clock));
            self.bursts.push_back(Burst { addr: m.araddr - self.base, beats: m.arlen + 1, first_clock });
            self.bursts_taken += 1;
        }
        if self.out.rvalid && m.rready {
            self.taken += 1;
            self.beats += 1;
            if self.out.rlast {
                self.bursts.pop_front();
                self.taken = 0;
            }
        }
        self.clock += 1;
        let pending = self.out.rvalid && !m.rready;
        let pause = self.timing.pause_in_256 > 0 && (self.x & 0xFF) < self.timing.pause_in_256;
        self.out.arready = (self.bursts.len() as u32) < self.timing.outstanding;
        match self.bursts.front() {
            Some(b) if pending || (b.first_clock <= self.clock && !pause) => {
                let at = (b.addr + (self.taken * self.beat_bytes) as u64) as usize;
                assert!(at + self.beat_bytes as usize <= self.image.len(), "read beyond the scene image: {at:#x}");
                self.out.rdata = self.image[at..at + self.beat_bytes as usize]
                    .iter()
                    .rev()
                    .fold(0u128, |v, &x| (v << 8) | x as u128);
                self.out.rvalid = true;
                self.out.rlast = self.taken + 1 == b.beats;
            }
            _ => {
                self.out.rvalid = false;
                self.out.rlast = false;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image() -> Vec<u8> {
        (0..4096u32).map(|k| (k * 7 + 3) as u8).collect()
    }

    /// Beats carry the image's bytes in order, the first `latency` clocks after the address,
    /// bursts in order, never more than `outstanding` taken, RVALID held while not taken.
    #[test]
    fn beats_come_in_order_after_the_latency() {
        for (latency, outstanding, extra, pause) in [(1, 1, 0, 0), (40, 4, 0, 0), (7, 16, 30, 90), (3, 2, 5, 200)] {
            let t = MemoryTiming { latency, outstanding, extra_delay: extra, pause_in_256: pause, seed: 99 };
            let mut m = MemoryModel::new(image(), 0x1000, 64, t);
            let wanted: Vec<u64> = (0..40).map(|k| 0x1000 + (k * 37 % 32) * 128).collect();
            let (mut asked, mut got, mut expect) = (0usize, Vec::new(), VecDeque::new());
            let mut taken_at = VecDeque::new();
            let mut rng = 5u32;
            for clock in 0..20_000u64 {
                rng = xorshift32(rng);
                let out = m.out().clone();
                let mo = MasterOut {
                    arvalid: asked < wanted.len(),
                    araddr: wanted.get(asked).copied().unwrap_or(0),
                    arlen: 15,
                    rready: rng & 3 != 0,
                };
                if mo.arvalid && out.arready {
                    taken_at.push_back(clock);
                    let a = (wanted[asked] - 0x1000) as usize;
                    for beat in 0..16 {
                        let bytes = &image()[a + 8 * beat..a + 8 * beat + 8];
                        expect.push_back(bytes.iter().rev().fold(0u128, |v, &x| (v << 8) | x as u128));
                    }
                    asked += 1;
                }
                assert!(taken_at.len() - got.len() / 16 <= outstanding as usize + 1);
                if out.rvalid && mo.rready {
                    let first_of_burst = got.len() % 16 == 0;
                    if first_of_burst {
                        let at = taken_at[got.len() / 16];
                        assert!(clock >= at + latency as u64, "beat at {clock}, address at {at}");
                    }
                    assert_eq!(out.rdata, expect.pop_front().unwrap());
                    assert_eq!(out.rlast, got.len() % 16 == 15);
                    got.push(out.rdata);
                }
                m.clock(&mo);
                if out.rvalid && !mo.rready {
                    assert!(m.out().rvalid && m.out().rdata == out.rdata, "a beat not taken must stay");
                }
            }
            assert_eq!(got.len(), 40 * 16, "{t:?}");
        }
    }

    #[test]
    fn xorshift_is_marsaglias() {
        // The sequence from 1: the HDL testbench models are checked against these.
        let mut x = 1;
        let seq: Vec<u32> = (0..3)
            .map(|_| {
                x = xorshift32(x);
                x
            })
            .collect();
        assert_eq!(seq, [270369, 67634689, 2647435461]);
    }
}
