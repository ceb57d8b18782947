// Stand-ins for the ECP5 primitives the board tops use, for simulation and lint only (the
// synthesis tools have the real ones): the ports and parameters of Lattice's EHXPLLL; CLKOP
// follows CLKI and LOCK rises after eight CLKI edges.
/* verilator lint_off UNUSED */
/* verilator lint_off DECLFILENAME */
module EHXPLLL #(
    parameter integer CLKI_DIV = 1, parameter integer CLKFB_DIV = 1, parameter integer CLKOP_DIV = 8,
    parameter integer CLKOS_DIV = 8, parameter integer CLKOS2_DIV = 8, parameter integer CLKOS3_DIV = 8,
    parameter CLKOP_ENABLE = "ENABLED", parameter CLKOS_ENABLE = "DISABLED",
    parameter CLKOS2_ENABLE = "DISABLED", parameter CLKOS3_ENABLE = "DISABLED",
    parameter integer CLKOP_CPHASE = 0, parameter integer CLKOS_CPHASE = 0,
    parameter integer CLKOS2_CPHASE = 0, parameter integer CLKOS3_CPHASE = 0,
    parameter integer CLKOP_FPHASE = 0, parameter integer CLKOS_FPHASE = 0,
    parameter integer CLKOS2_FPHASE = 0, parameter integer CLKOS3_FPHASE = 0,
    parameter FEEDBK_PATH = "CLKOP", parameter CLKOP_TRIM_POL = "RISING",
    parameter integer CLKOP_TRIM_DELAY = 0, parameter CLKOS_TRIM_POL = "RISING",
    parameter integer CLKOS_TRIM_DELAY = 0, parameter OUTDIVIDER_MUXA = "DIVA",
    parameter OUTDIVIDER_MUXB = "DIVB", parameter OUTDIVIDER_MUXC = "DIVC",
    parameter OUTDIVIDER_MUXD = "DIVD", parameter integer PLL_LOCK_MODE = 0,
    parameter integer PLL_LOCK_DELAY = 200, parameter STDBY_ENABLE = "DISABLED",
    parameter REFIN_RESET = "DISABLED", parameter SYNC_ENABLE = "DISABLED",
    parameter INT_LOCK_STICKY = "ENABLED", parameter DPHASE_SOURCE = "DISABLED",
    parameter PLLRST_ENA = "DISABLED", parameter INTFB_WAKE = "DISABLED"
) (
    input wire CLKI, input wire CLKFB, input wire PHASESEL1, input wire PHASESEL0,
    input wire PHASEDIR, input wire PHASESTEP, input wire PHASELOADREG, input wire STDBY,
    input wire PLLWAKESYNC, input wire RST, input wire ENCLKOP, input wire ENCLKOS,
    input wire ENCLKOS2, input wire ENCLKOS3,
    output wire CLKOP, output wire CLKOS, output wire CLKOS2, output wire CLKOS3,
    output wire LOCK, output wire INTLOCK, output wire REFCLK, output wire CLKINTFB
);
    reg [3:0] edges = 4'd0;
    always @(posedge CLKI) if (!edges[3]) edges <= edges + 4'd1;
    assign CLKOP = CLKI;
    assign {CLKOS, CLKOS2, CLKOS3, REFCLK, CLKINTFB} = 5'b0;
    assign LOCK = edges[3];
    assign INTLOCK = edges[3];
endmodule
/* verilator lint_on UNUSED */
