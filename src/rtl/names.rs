//! Emitted identifiers: legal in VHDL-93 and Verilog-2001 at once, readable, stable.

/// Names no emitted identifier may take: VHDL-93 and Verilog-2001 keywords, the names of
/// the library functions and types the VHDL printer calls (a signal named `resize` hides
/// numeric_std's `resize`), the ports the printers add themselves (`clk`, `rst`) and the
/// attribute the VHDL printer declares (`keep`).
const RESERVED: &str = "
abs access after alias all always and architecture array assert assign attribute begin block body
buf buffer bufif0 bufif1 bus case casex casez clk cmos component configuration constant deassign
default defparam disable disconnect downto edge else elsif end endcase endfunction endgenerate
endmodule endprimitive endspecify endtable endtask entity event exit file for force forever fork
function generate generic genvar group guarded highz0 highz1 if impure in inertial initial inout
input integer is join label large library linkage literal localparam loop macromodule map medium mod
module nand negedge new next nmos nor not notif0 notif1 null of on open or others out output package
parameter pmos port posedge postponed primitive procedure process pull0 pull1 pulldown pullup pure
range rcmos real record reg register reject release rem repeat report return rnmos rol ror rpmos rst
scalared select severity shared signal signed sla sll small specify sra srl strong0 strong1 subtype
supply0 supply1 table task then time to tran transport tri tri0 tri1 triand trior trireg type
unaffected units unsigned until use variable vectored wait wand weak0 weak1 when while wire with wor
xnor xor
ieee std work numeric_std std_logic_1164 std_logic std_logic_vector std_ulogic boolean natural
resize shift_left shift_right rotate_left rotate_right to_integer to_signed to_unsigned
rising_edge falling_edge
automatic cell config design endconfig incdir include instance liblist noshowcancelled
pulsestyle_ondetect pulsestyle_onevent showcancelled specparam realtime ifnone tranif0 tranif1
rtran rtranif0 rtranif1 uwire
logic bit byte int shortint longint string unique priority local const static void enum struct
union typedef class extends package import export interface modport program property sequence
assert assume cover bind chandle final foreach inside new null ref return this var virtual
wildcard with alias always_comb always_ff always_latch break continue do iff
keep";

pub fn is_reserved(s: &str) -> bool {
    RESERVED.split_whitespace().any(|w| w == s)
}

/// `base` made into a legal identifier for both languages: lower case, [a-z0-9_], starting
/// with a letter, no double or trailing underscore, not a keyword. Uniqueness is the caller's.
pub fn legal(base: &str) -> String {
    let mut s: String =
        base.to_ascii_lowercase().chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '_' }).collect();
    while s.contains("__") {
        s = s.replace("__", "_");
    }
    let mut s = s.trim_matches('_').to_string();
    if s.is_empty() {
        s = "s".to_string();
    } else if !s.starts_with(|c: char| c.is_ascii_alphabetic()) {
        s = format!("s_{s}");
    }
    if is_reserved(&s) {
        s.push_str("_s");
    }
    s
}
