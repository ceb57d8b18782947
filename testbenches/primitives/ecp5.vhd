-- Stand-in for the ECP5 EHXPLLL the ULX3S top uses, for simulation only (the synthesis tools
-- have the real one): its generics and ports; CLKOP follows CLKI and LOCK rises after eight
-- CLKI edges.
library ieee;
use ieee.std_logic_1164.all;

entity EHXPLLL is
  generic (
    CLKI_DIV : integer := 1; CLKFB_DIV : integer := 1; CLKOP_DIV : integer := 8;
    CLKOS_DIV : integer := 8; CLKOS2_DIV : integer := 8; CLKOS3_DIV : integer := 8;
    CLKOP_ENABLE : string := "ENABLED"; CLKOS_ENABLE : string := "DISABLED";
    CLKOS2_ENABLE : string := "DISABLED"; CLKOS3_ENABLE : string := "DISABLED";
    CLKOP_CPHASE : integer := 0; CLKOS_CPHASE : integer := 0; CLKOS2_CPHASE : integer := 0;
    CLKOS3_CPHASE : integer := 0; CLKOP_FPHASE : integer := 0; CLKOS_FPHASE : integer := 0;
    CLKOS2_FPHASE : integer := 0; CLKOS3_FPHASE : integer := 0;
    FEEDBK_PATH : string := "CLKOP"; CLKOP_TRIM_POL : string := "RISING";
    CLKOP_TRIM_DELAY : integer := 0; CLKOS_TRIM_POL : string := "RISING";
    CLKOS_TRIM_DELAY : integer := 0; OUTDIVIDER_MUXA : string := "DIVA";
    OUTDIVIDER_MUXB : string := "DIVB"; OUTDIVIDER_MUXC : string := "DIVC";
    OUTDIVIDER_MUXD : string := "DIVD"; PLL_LOCK_MODE : integer := 0;
    PLL_LOCK_DELAY : integer := 200; STDBY_ENABLE : string := "DISABLED";
    REFIN_RESET : string := "DISABLED"; SYNC_ENABLE : string := "DISABLED";
    INT_LOCK_STICKY : string := "ENABLED"; DPHASE_SOURCE : string := "DISABLED";
    PLLRST_ENA : string := "DISABLED"; INTFB_WAKE : string := "DISABLED");
  port (
    CLKI, CLKFB, PHASESEL1, PHASESEL0, PHASEDIR, PHASESTEP, PHASELOADREG, STDBY,
    PLLWAKESYNC, RST, ENCLKOP, ENCLKOS, ENCLKOS2, ENCLKOS3 : in std_logic;
    CLKOP, CLKOS, CLKOS2, CLKOS3, LOCK, INTLOCK, REFCLK, CLKINTFB : out std_logic);
end entity;

architecture stand_in of EHXPLLL is
  signal edges : integer range 0 to 8 := 0;
begin
  process (CLKI)
  begin
    if rising_edge(CLKI) and edges < 8 then
      edges <= edges + 1;
    end if;
  end process;
  CLKOP <= CLKI;
  CLKOS <= '0'; CLKOS2 <= '0'; CLKOS3 <= '0'; REFCLK <= '0'; CLKINTFB <= '0';
  LOCK <= '1' when edges = 8 else '0';
  INTLOCK <= '1' when edges = 8 else '0';
end architecture;
