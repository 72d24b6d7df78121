// ECS image (identity 11): the ECS host writes PWM and reads encoder counts.
// Block diagram: board_link (por, spi_slave, frame_engine) <-> board_ecs (pwm_generator x4,
// quad_decoder x4); por resets everything but the SPI front end. See docs/fpga.md.
module icoboard (
  input  wire       clk,          // 100 MHz oscillator
  input  wire       spi_sclk,
  input  wire       spi_mosi,
  // CS is both the asynchronous reset of the SCLK-domain bit counters and the input of a
  // two-flop synchroniser into clk (spi_slave.v): deliberate, hence the waiver.
  /* verilator lint_off SYNCASYNCNET */
  input  wire       spi_cs_n,
  /* verilator lint_on SYNCASYNCNET */
  output wire       spi_miso,
  output wire [3:0] pwm_out,      // PWM generators, 24.4 kHz
  output wire [3:0] pwm_dir,      // dir 1 = negative
  input  wire [3:0] enc_a,        // quadrature decoder inputs
  input  wire [3:0] enc_b,
  input  wire [3:0] pin_in,       // digital inputs  (answer words' bit 14)
  output wire [3:0] pin_out       // digital outputs (request words' bit 14)
);
  wire        rst, clr, init_go, init_done, init_ok, all_go, pulse_limit;
  wire [15:0] init_divider;
  wire [63:0] payload, pwm_words, enc_words;

  board_link #(.TWIN(0), .IDENTITY(8'd11)) u_link (
    .clk(clk), .spi_sclk(spi_sclk), .spi_mosi(spi_mosi), .spi_cs_n(spi_cs_n),
    .spi_miso(spi_miso), .rst(rst), .clr(clr), .init_go(init_go), .init_done(init_done),
    .init_ok(init_ok), .init_divider(init_divider), .all_go(all_go), .payload(payload),
    .pwm_words(pwm_words), .enc_words(enc_words), .pulse_limit(pulse_limit)
  );

  board_ecs u_board (
    .clk(clk), .rst(rst), .clr(clr), .init_go(init_go), .init_done(init_done),
    .init_ok(init_ok), .init_divider(init_divider), .all_go(all_go), .payload(payload),
    .pwm_words(pwm_words), .enc_words(enc_words), .pulse_limit(pulse_limit),
    .pwm_out(pwm_out), .pwm_dir(pwm_dir), .enc_a(enc_a), .enc_b(enc_b),
    .pin_in(pin_in), .pin_out(pin_out)
  );
endmodule
