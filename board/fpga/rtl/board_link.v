// The SPI side both images share: power-on reset, the SPI slave (SCLK domain and its crossing
// into clk) and the frame engine (checks, acts, answers; pipelined by one transfer). Each top
// wires it to its own board (board_ecs or board_twin) through the engine's board interface.
module board_link #(
  parameter TWIN = 0,                 // 1: icoboard_inverse
  parameter [7:0] IDENTITY = 8'd11
) (
  input  wire        clk,
  input  wire        spi_sclk,
  input  wire        spi_mosi,
  // CS is both the asynchronous reset of the SCLK-domain bit counters and the input of a
  // two-flop synchroniser into clk (spi_slave.v): deliberate, hence the waiver.
  /* verilator lint_off SYNCASYNCNET */
  input  wire        spi_cs_n,
  /* verilator lint_on SYNCASYNCNET */
  output wire        spi_miso,
  // board interface (see frame_engine.v)
  output wire        rst,
  output wire        clr,
  output wire        init_go,
  input  wire        init_done,
  input  wire        init_ok,
  input  wire [15:0] init_divider,
  output wire        all_go,
  output wire [63:0] payload,
  input  wire [63:0] pwm_words,
  input  wire [63:0] enc_words,
  input  wire        pulse_limit
);
  wire        take, pending, cs_idle;
  wire [95:0] request, answer;

  por u_por (.clk(clk), .rst(rst));

  spi_slave u_spi (
    .clk(clk), .rst(rst), .spi_sclk(spi_sclk), .spi_mosi(spi_mosi), .spi_cs_n(spi_cs_n),
    .spi_miso(spi_miso), .answer(answer), .take(take), .pending(pending), .request(request),
    .cs_idle(cs_idle)
  );

  frame_engine #(.TWIN(TWIN), .IDENTITY(IDENTITY)) u_engine (
    .clk(clk), .rst(rst), .pending(pending), .take(take), .request(request), .cs_idle(cs_idle),
    .answer(answer), .clr(clr), .init_go(init_go), .init_done(init_done), .init_ok(init_ok),
    .init_divider(init_divider), .all_go(all_go), .payload(payload), .pwm_words(pwm_words),
    .enc_words(enc_words), .pulse_limit(pulse_limit)
  );
endmodule
