// Stand-in tops with the ports of spec15 §3, used only until fpga/rtl/ exists: an SPI slave
// whose answer register holds the previous request (an echo), so the harness can be built and
// its timing checked. Deleted once the real images arrive.
module standin_core (
  input  wire clk, spi_sclk, spi_mosi, spi_cs_n,
  output wire spi_miso
);
  reg [6:0] rx_count; reg [6:0] tx_count; reg [95:0] shift; reg [95:0] holding;
  reg toggle = 1'b0; reg [2:0] tsync = 3'b0; reg [1:0] csync = 2'b11; reg [95:0] answer = 96'd0;
  reg [95:0] pending = 96'd0; reg have = 1'b0;
  always @(posedge spi_sclk or posedge spi_cs_n)
    if (spi_cs_n) rx_count <= 7'd0; else if (rx_count != 7'd96) rx_count <= rx_count + 7'd1;
  always @(posedge spi_sclk) begin
    if (rx_count < 7'd96) shift <= {shift[94:0], spi_mosi};
    if (rx_count == 7'd95) begin holding <= {shift[94:0], spi_mosi}; toggle <= ~toggle; end
  end
  always @(negedge spi_sclk or posedge spi_cs_n)
    if (spi_cs_n) tx_count <= 7'd0; else if (tx_count != 7'd96) tx_count <= tx_count + 7'd1;
  assign spi_miso = tx_count < 7'd96 ? answer[7'd95 - tx_count] : 1'b0;
  always @(posedge clk) begin
    tsync <= {tsync[1:0], toggle};
    csync <= {csync[0], spi_cs_n};
    if (tsync[2] != tsync[1]) begin pending <= holding; have <= 1'b1; end
    else if (have && csync[1]) begin answer <= pending; have <= 1'b0; end
  end
endmodule

module icoboard_inverse (
  input wire clk, spi_sclk, spi_mosi, spi_cs_n, output wire spi_miso,
  input wire [3:0] pwm_in, pwm_dir_in, output wire [3:0] enc_a, enc_b,
  input wire [3:0] pin_in, output wire [3:0] pin_out);
  standin_core core (.clk(clk), .spi_sclk(spi_sclk), .spi_mosi(spi_mosi), .spi_cs_n(spi_cs_n),
                     .spi_miso(spi_miso));
  reg [3:0] a = 4'd0;
  always @(posedge clk) a <= pwm_in ^ pwm_dir_in ^ pin_in;
  assign enc_a = a; assign enc_b = 4'd0; assign pin_out = 4'd0;
endmodule

module icoboard (
  input wire clk, spi_sclk, spi_mosi, spi_cs_n, output wire spi_miso,
  output wire [3:0] pwm_out, pwm_dir, input wire [3:0] enc_a, enc_b,
  input wire [3:0] pin_in, output wire [3:0] pin_out);
  standin_core core (.clk(clk), .spi_sclk(spi_sclk), .spi_mosi(spi_mosi), .spi_cs_n(spi_cs_n),
                     .spi_miso(spi_miso));
  reg [3:0] p = 4'd0;
  always @(posedge clk) p <= enc_a ^ enc_b ^ pin_in;
  assign pwm_out = p; assign pwm_dir = 4'd0; assign pin_out = 4'd0;
endmodule
