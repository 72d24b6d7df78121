// SPI slave front end, mode 0 (CPOL 0, CPHA 0), MSB first, 96-bit frames (spec15 §1, §3).
//
// SCLK domain (the only logic not clocked by `clk`):
//  * rx_count counts rising SCLK edges; it is reset asynchronously while CS is high, so every
//    transfer starts at bit 0 whatever the previous one did (a short transfer is forgotten).
//    Only CS ends a transfer: a host that keeps CS low across two frames gets the second one
//    ignored, so every transfer must be framed by CS (docs/spi-protocol.md). Both bit counters
//    also start at 0 (iCE40 flip-flops configure to 0, as por.v relies on): CS is high from
//    power-up, so no CS edge resets them before the first transfer, and a simulator would
//    otherwise start with X on MISO and frame the first request at an arbitrary bit.
//  * shift collects MOSI; on the 96th rising edge the whole request is copied into `holding` and
//    `toggle` flips. `holding` is then left alone until the 96th edge of a later transfer, i.e.
//    for at least 95 SCLK periods (3 us at 31.25 MHz).
//  * MISO is answer[95 - tx_count], where tx_count counts falling edges (also reset while CS is
//    high): bit 95 (byte 0 MSB) is on the line as soon as CS falls, the next bit after each
//    falling edge, as mode 0 requires. Beyond 96 clocks MISO is 0.
//
// Crossing into the 100 MHz domain: `toggle` passes a two-flop synchroniser; a change of its
// synchronised value means "a new request sits in holding". holding was written on the same
// SCLK edge that flipped toggle, so it has settled long before the synchronised toggle is seen
// (>= 1 clk later) and stays stable for >= 95 SCLK periods, while the copy happens within a few
// clocks. The event is kept pending (synchronised toggle != `seen`) until the frame engine takes
// it, so a request arriving while the engine still waits to publish an answer is not lost.
// The answer register (in the frame engine) is written only while the synchronised CS is high,
// so MISO never changes in the middle of a transfer.
module spi_slave (
  input  wire        clk,
  input  wire        rst,
  input  wire        spi_sclk,
  input  wire        spi_mosi,
  input  wire        spi_cs_n,
  output wire        spi_miso,
  input  wire [95:0] answer,       // clk domain; changes only while CS is high
  input  wire        take,         // engine takes the pending request (copies holding)
  output wire        pending,      // a complete request waits in holding
  output reg  [95:0] request,      // clk-domain copy of holding, valid from the clock after take
  output wire        cs_idle       // synchronised CS (1 = no transfer in progress)
);
  // ---- SCLK domain -------------------------------------------------------------------------
  reg [6:0]  rx_count = 7'd0;
  reg [6:0]  tx_count = 7'd0;
  reg [94:0] shift;
  reg [95:0] holding;
  reg        toggle = 1'b0;

  always @(posedge spi_sclk or posedge spi_cs_n) begin
    if (spi_cs_n) rx_count <= 7'd0;
    else if (rx_count != 7'd96) rx_count <= rx_count + 7'd1;
  end

  always @(posedge spi_sclk) begin
    if (rx_count < 7'd95) shift <= {shift[93:0], spi_mosi};
    if (rx_count == 7'd95) begin
      holding <= {shift, spi_mosi};
      toggle  <= ~toggle;
    end
  end

  always @(negedge spi_sclk or posedge spi_cs_n) begin
    if (spi_cs_n) tx_count <= 7'd0;
    else if (tx_count != 7'd96) tx_count <= tx_count + 7'd1;
  end

  wire [6:0] tx_index = 7'd95 - tx_count;
  assign spi_miso = (tx_count < 7'd96) ? answer[tx_index] : 1'b0;

  // ---- 100 MHz domain ------------------------------------------------------------------------
  wire toggle_s;
  reg  seen = 1'b0;

  sync2 u_sync_toggle (.clk(clk), .d(toggle), .q(toggle_s));
  sync2 u_sync_cs     (.clk(clk), .d(spi_cs_n), .q(cs_idle));

  // During reset `seen` follows the toggle, so whatever value the toggle powered up with is not
  // taken for a request.
  assign pending = !rst && (toggle_s != seen);

  always @(posedge clk) begin
    if (rst) begin
      seen <= toggle_s;
    end else if (take) begin
      seen    <= toggle_s;
      request <= holding;
    end
  end
endmodule
