# nextpnr-ice40 --pre-pack script: constrain the SPI clock as well as clk (--freq 100), so a
# path in the SCLK domain slower than the Raspberry Pi's 31.25 MHz fails the build too.
ctx.addClock("spi_sclk", 31.25)
