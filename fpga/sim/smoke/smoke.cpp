// Throwaway smoke check of the twin image: INIT, ALL, TEST, fetch NOOPs at 31.25 MHz SCLK.
// Build: verilator --cc --exe --build -Wno-fatal --top-module icoboard_inverse
//        ../../rtl/*.v smoke.cpp -o smoke   (the cosim helper's tests are the real ones)
#include <cstdint>
#include <cstdio>
#include <vector>
#include "Vicoboard_inverse.h"

static Vicoboard_inverse* top;
static uint64_t ps = 0;        // picoseconds
static uint64_t next_clk = 5000;
static void advance_to(uint64_t t) {
  while (next_clk <= t) { ps = next_clk; top->clk = !top->clk; top->eval(); next_clk += 5000; }
  ps = t; top->eval();
}
static uint8_t crc8(const uint8_t* d, int n) {
  uint8_t c = 0xFF;
  for (int i = 0; i < n; ++i) { c ^= d[i]; for (int b = 0; b < 8; ++b) c = (c & 0x80) ? (c << 1) ^ 0x2F : (c << 1); }
  return c ^ 0xFF;
}
static std::vector<uint8_t> transfer(std::vector<uint8_t> req) {
  const uint64_t half = 16000;  // 31.25 MHz
  req[11] = crc8(req.data(), 11);
  std::vector<uint8_t> ans(12, 0);
  top->spi_cs_n = 0; advance_to(ps + half);
  for (int bit = 0; bit < 96; ++bit) {
    top->spi_mosi = (req[bit / 8] >> (7 - bit % 8)) & 1;
    advance_to(ps + 1); 
    top->spi_sclk = 1; top->eval();
    ans[bit / 8] |= top->spi_miso << (7 - bit % 8);
    advance_to(ps + half);
    top->spi_sclk = 0; top->eval();
    advance_to(ps + half);
  }
  top->spi_cs_n = 1; advance_to(ps + 2000000);  // 2 us
  return ans;
}
static void show(const char* n, const std::vector<uint8_t>& a) {
  printf("%-10s", n); for (auto b : a) printf(" %02X", b);
  printf("  crc %s\n", crc8(a.data(), 11) == a[11] ? "ok" : "BAD");
}
int main() {
  top = new Vicoboard_inverse;
  top->spi_cs_n = 1; top->spi_sclk = 0; top->pwm_in = 0x1; top->pwm_dir_in = 0; top->pin_in = 0x2;
  advance_to(1000000);
  transfer({1, 1, 0x00, 0x03, 0xD0, 0x90, 0x00, 0x00, 0x00, 0x04, 0, 0});
  show("init-ans", transfer({0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}));
  transfer({3, 3, 0x00, 0x64, 0x3F, 0x9C, 0x1F, 0xFF, 0x60, 0x00, 0, 0});
  show("all-ans", transfer({0, 4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}));
  transfer({12, 5, 0xDE, 0xAD, 0xBE, 0xEF, 1, 0x23, 0x45, 0x67, 0, 0});
  show("test-ans", transfer({0, 6, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}));
  auto bad = std::vector<uint8_t>{0, 7, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  transfer({8, 8, 0, 0x64, 0, 0, 0, 0, 0, 0, 0, 0});
  show("enc0-ans", transfer({0, 9, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}));
  int edges = 0; int last = top->enc_a & 1;
  for (int i = 0; i < 300000; ++i) { advance_to(ps + 10000); if ((top->enc_a & 1) != last) { ++edges; last = top->enc_a & 1; } }
  printf("A0 edges in 3 ms: %d (expect 50 for 100 counts)\n", edges);
  transfer({3, 10, 0x00, 0x64, 0x3F, 0x9C, 0x1F, 0xFF, 0x60, 0x00, 0, 0});
  show("all2-ans", transfer({0, 11, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}));
  delete top;
}
