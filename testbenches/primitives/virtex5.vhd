-- Stand-ins for the Virtex-5 PLL_BASE and BUFG the ML509 top uses, for simulation only (ISE
-- has the real ones in UNISIM): the generics set and the ports; CLKOUT0 follows CLKIN and
-- LOCKED rises after eight CLKIN edges.
library ieee;
use ieee.std_logic_1164.all;

entity PLL_BASE is
  generic (
    CLKIN_PERIOD : real := 0.0; DIVCLK_DIVIDE : integer := 1; CLKFBOUT_MULT : integer := 1;
    CLKOUT0_DIVIDE : integer := 1; COMPENSATION : string := "SYSTEM_SYNCHRONOUS");
  port (
    CLKIN, CLKFBIN, RST : in std_logic;
    CLKFBOUT, CLKOUT0, CLKOUT1, CLKOUT2, CLKOUT3, CLKOUT4, CLKOUT5, LOCKED : out std_logic);
end entity;

architecture stand_in of PLL_BASE is
  signal edges : integer range 0 to 8 := 0;
begin
  process (CLKIN)
  begin
    if rising_edge(CLKIN) and edges < 8 then
      edges <= edges + 1;
    end if;
  end process;
  CLKFBOUT <= CLKIN;
  CLKOUT0 <= CLKIN;
  CLKOUT1 <= '0'; CLKOUT2 <= '0'; CLKOUT3 <= '0'; CLKOUT4 <= '0'; CLKOUT5 <= '0';
  LOCKED <= '1' when edges = 8 else '0';
end architecture;

library ieee;
use ieee.std_logic_1164.all;

entity BUFG is
  port (I : in std_logic; O : out std_logic);
end entity;

architecture stand_in of BUFG is
begin
  O <= I;
end architecture;
