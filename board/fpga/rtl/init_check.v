// INIT on the twin image (spec15 §2): accepted iff step_ns >= 10, 4 <= D <= 65535 and
// 1 <= S <= 65535 with S = floor(floor(step_ns / 10) / D). Two passes of one sequential divider
// (about 70 clocks in all), well inside the 150 clocks the answer may take.
module init_check (
  input  wire        clk,
  input  wire        rst,
  input  wire        go,          // one-clock pulse: check these parameters
  input  wire [31:0] step_ns,
  input  wire [31:0] divider,
  output reg         done,        // one-clock pulse
  output reg         ok,
  output reg  [15:0] subticks,    // S, valid with done && ok
  output reg  [15:0] clock_div    // D, valid with done && ok
);
  localparam [1:0] IDLE = 2'd0, DIV10 = 2'd1, DIVD = 2'd2;
  reg  [1:0]  state;
  reg         div_start;
  reg  [31:0] div_dividend;
  reg  [15:0] div_divisor;
  wire        div_done;
  wire [31:0] div_quotient;

  seq_divider u_div (
    .clk(clk), .start(div_start), .dividend(div_dividend), .divisor(div_divisor),
    .done(div_done), .quotient(div_quotient)
  );

  // Registered: the request (and so step_ns, divider) is stable from the frame engine's take,
  // a dozen clocks before go; this keeps the 32-bit compares off the go path.
  reg step_ok, divider_ok;
  always @(posedge clk) begin
    step_ok    <= (step_ns[31:4] != 28'd0) || (step_ns[3:0] >= 4'd10);          // >= 10
    divider_ok <= (divider[31:16] == 16'd0) && (divider[15:2] != 14'd0);        // 4..65535
  end
  wire range_ok = step_ok && divider_ok;

  always @(posedge clk) begin
    done      <= 1'b0;
    div_start <= 1'b0;
    if (rst) begin
      state <= IDLE;
      ok    <= 1'b0;
    end else begin
      case (state)
        IDLE: if (go) begin
          clock_div <= divider[15:0];
          if (range_ok) begin
            div_dividend <= step_ns;
            div_divisor  <= 16'd10;
            div_start    <= 1'b1;
            state        <= DIV10;
          end else begin
            ok   <= 1'b0;
            done <= 1'b1;
          end
        end
        DIV10: if (div_done) begin
          div_dividend <= div_quotient;     // step in 100 MHz clocks
          div_divisor  <= clock_div;
          div_start    <= 1'b1;
          state        <= DIVD;
        end
        DIVD: if (div_done) begin
          ok       <= (div_quotient != 32'd0) && (div_quotient[31:16] == 16'd0);
          subticks <= div_quotient[15:0];
          done     <= 1'b1;
          state    <= IDLE;
        end
        default: state <= IDLE;
      endcase
    end
  end
endmodule
