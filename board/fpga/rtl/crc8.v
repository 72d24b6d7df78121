// One byte step of CRC-8/AUTOSAR (poly 0x2F, init 0xFF, xorout 0xFF, no reflection), as
// io::Crc8's table entry kCrcTable[crc ^ byte]. Purely combinational: the frame engine feeds it
// one byte per clock (11 clocks per frame), which keeps the XOR tree 8 bits deep instead of 88.
module crc8 (
  input  wire [7:0] crc_in,
  input  wire [7:0] data,
  output reg  [7:0] crc_out
);
  integer bit_index;
  reg [7:0] c;

  always @(*) begin
    c = crc_in ^ data;
    for (bit_index = 0; bit_index < 8; bit_index = bit_index + 1) begin
      c = c[7] ? ({c[6:0], 1'b0} ^ 8'h2F) : {c[6:0], 1'b0};
    end
    crc_out = c;
  end
endmodule
