// Twin image (identity 22): the twin's host writes encoder positions and reads PWM.
// Block diagram: board_link (por, spi_slave, frame_engine) <-> board_twin (pwm_reader x4,
// encoder_emulator x4, subtick_timer, init_check); por resets everything but the SPI front end.
// See docs/fpga.md.
module icoboard_inverse (
  input  wire       clk,          // 100 MHz oscillator
  input  wire       spi_sclk,
  input  wire       spi_mosi,
  // CS is both the asynchronous reset of the SCLK-domain bit counters and the input of a
  // two-flop synchroniser into clk (spi_slave.v): deliberate, hence the waiver.
  /* verilator lint_off SYNCASYNCNET */
  input  wire       spi_cs_n,
  /* verilator lint_on SYNCASYNCNET */
  output wire       spi_miso,
  input  wire [3:0] pwm_in,       // PWM reader inputs (from the ECS board's generators)
  input  wire [3:0] pwm_dir_in,   // direction lines (1 = negative)
  output wire [3:0] enc_a,        // encoder emulator outputs (A leads B counting up)
  output wire [3:0] enc_b,
  input  wire [3:0] pin_in,       // digital inputs  (answer words' bit 14)
  output wire [3:0] pin_out       // digital outputs (request words' bit 14)
);
  wire        rst, clr, init_go, init_done, init_ok, all_go, pulse_limit;
  wire [15:0] init_divider;
  wire [63:0] payload, pwm_words, enc_words;

  board_link #(.TWIN(1), .IDENTITY(8'd22)) u_link (
    .clk(clk), .spi_sclk(spi_sclk), .spi_mosi(spi_mosi), .spi_cs_n(spi_cs_n),
    .spi_miso(spi_miso), .rst(rst), .clr(clr), .init_go(init_go), .init_done(init_done),
    .init_ok(init_ok), .init_divider(init_divider), .all_go(all_go), .payload(payload),
    .pwm_words(pwm_words), .enc_words(enc_words), .pulse_limit(pulse_limit)
  );

  board_twin u_board (
    .clk(clk), .rst(rst), .clr(clr), .init_go(init_go), .init_done(init_done),
    .init_ok(init_ok), .init_divider(init_divider), .all_go(all_go), .payload(payload),
    .pwm_words(pwm_words), .enc_words(enc_words), .pulse_limit(pulse_limit),
    .pwm_in(pwm_in), .pwm_dir_in(pwm_dir_in), .enc_a(enc_a), .enc_b(enc_b),
    .pin_in(pin_in), .pin_out(pin_out)
  );
endmodule
