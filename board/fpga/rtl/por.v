// Power-on reset: the IcoBoard has no reset pin wired to the FPGA, so reset comes from a
// counter. iCE40 flip-flops configure to 0, and the declaration initialisers below say the same
// thing to yosys and Verilator, so `rst` is high for the first 16 clocks after configuration.
module por (
  input  wire clk,
  output reg  rst
);
  reg [3:0] count = 4'd0;

  initial rst = 1'b1;

  always @(posedge clk) begin
    if (count != 4'hF) count <= count + 4'd1;
    rst <= (count != 4'hF);
  end
endmodule
