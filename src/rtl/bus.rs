//! Ports wider than a signal may be (`width::MAX_WIDTH`), such as the 512-bit `tdata` of an
//! AXI4-Stream port: a **bus** is a list of ordinary ports of one module (its parts, least
//! significant first) that the printers show as one port — a `std_logic_vector` in VHDL, a
//! plain vector in Verilog — with the parts as internal signals assigned from its slices (or
//! assigned to them). The simulators, the flattener and everything else see only the parts, so
//! nothing below the printed interface changes.
//!
//! A module with buses is a top level: the printers do not instantiate one (its component
//! would have the bus, its instance the parts).

pub use super::netlist::Bus;
use super::netlist::{Module, SigId};
use super::width::Ty;

/// A port as the printers show it (the clock and reset aside).
pub struct PrintedPort<'a> {
    pub name: &'a str,
    pub input: bool,
    /// Unsigned, as wide as all its parts, for a bus (wider than a signal may be).
    pub ty: Ty,
    pub bus: Option<&'a Bus>,
}

impl Module {
    /// Makes the ports named `parts` — all inputs or all outputs, unsigned, least significant
    /// first — one printed port `name`.
    pub fn bus(&mut self, name: &str, parts: &[&str]) {
        let find = |p: &str| -> (bool, usize) {
            let input = self.inputs.iter().position(|&i| self.sig(i).name == p);
            let output = self.outputs.iter().position(|o| o.0 == p);
            match (input, output) {
                (Some(k), None) => (true, k),
                (None, Some(k)) => (false, k),
                _ => panic!("{}: bus {name}: no port {p}", self.name),
            }
        };
        let found: Vec<(bool, usize)> = parts.iter().map(|p| find(p)).collect();
        let input = found[0].0;
        assert!(found.iter().all(|f| f.0 == input), "{}: bus {name} mixes inputs and outputs", self.name);
        for (p, &(_, k)) in parts.iter().zip(&found) {
            assert!(!self.port_sig(input, k).ty.signed, "{}: bus {name}: part {p} is signed", self.name);
            assert!(self.bus_part(input, k).is_none(), "{}: bus {name}: {p} is already in a bus", self.name);
        }
        let legal = super::names::legal(name);
        assert!(legal == name && !self.idents.contains(name), "{}: bus name {name} is taken or not legal", self.name);
        self.idents.insert(name.to_string());
        self.buses.push(Bus { name: name.to_string(), input, parts: found.iter().map(|f| f.1).collect() });
    }

    /// The signal of input `k` or of output `k`.
    fn port_sig(&self, input: bool, k: usize) -> super::netlist::Sig {
        self.handle(if input { self.inputs[k] } else { self.outputs[k].1 })
    }

    /// The bus input `k` (or output `k`) is a part of, and the part's lowest bit in it.
    pub fn bus_part(&self, input: bool, k: usize) -> Option<(&Bus, u32)> {
        self.buses.iter().filter(|b| b.input == input).find_map(|b| {
            let at = b.parts.iter().position(|&p| p == k)?;
            Some((b, b.parts[..at].iter().map(|&p| self.port_sig(input, p).ty.width).sum()))
        })
    }

    /// Whether signal `id` is an input that is a part of a bus.
    pub fn is_bus_input(&self, id: SigId) -> bool {
        self.inputs.iter().position(|&i| i == id).is_some_and(|k| self.bus_part(true, k).is_some())
    }

    /// The bits of a bus.
    pub fn bus_width(&self, bus: &Bus) -> u32 {
        bus.parts.iter().map(|&p| self.port_sig(bus.input, p).ty.width).sum()
    }

    /// The ports as printed, inputs then outputs: a bus in place of its first part, its other
    /// parts left out.
    pub fn printed_ports(&self) -> Vec<PrintedPort<'_>> {
        let mut out = Vec::new();
        for input in [true, false] {
            let count = if input { self.inputs.len() } else { self.outputs.len() };
            for k in 0..count {
                match self.bus_part(input, k) {
                    Some((bus, 0)) => {
                        out.push(PrintedPort { name: &bus.name, input, ty: Ty::u(self.bus_width(bus)), bus: Some(bus) })
                    }
                    Some(_) => {}
                    None => {
                        let name = if input { &self.sig(self.inputs[k]).name } else { &self.outputs[k].0 };
                        out.push(PrintedPort { name, input, ty: self.port_sig(input, k).ty, bus: None })
                    }
                }
            }
        }
        out
    }
}
