// hiltwin_controller_probe LIBRARY STEP_S INPUTS [INPUTS...]: loads a C ABI controller with the
// loader (abi_controller.h), starts it at STEP_S seconds and steps it once per INPUTS (the
// input values, comma-separated, in port order), printing each step's outputs as
// "step <k>: <name>=<value> ..." with every digit. Exit 0; 1 when a step returned an error
// (its text on stderr); 2 when the library is refused (the message on stderr). A library that
// crashes kills it, which is what the crash test wants to see from outside.
#include <cstdio>
#include <exception>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "hiltwin/controller/abi_controller.h"

namespace {

std::vector<double> ParseValues(const std::string& text) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) values.push_back(std::stod(item));
  return values;
}

int Probe(int argc, char** argv) {
  using hiltwin::controller::Controller;
  const std::unique_ptr<Controller> controller = hiltwin::controller::LoadAbiController(argv[1]);
  controller->Start(std::stod(argv[2]));
  const auto& info = controller->Info();
  std::vector<double> out(info.outputs.size());
  for (int k = 3; k < argc; ++k) {
    const std::vector<double> in = ParseValues(argv[k]);
    const auto status = controller->Step(in, out);
    if (!status.ok()) {
      std::fprintf(stderr, "step %d: error: %s\n", k - 2, status.reason);
      return 1;
    }
    std::printf("step %d:", k - 2);
    for (std::size_t i = 0; i < out.size(); ++i) {
      std::printf(" %s=%.17g", info.outputs[i].name.c_str(), out[i]);
    }
    std::printf("\n");
  }
  controller->Finish();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s LIBRARY STEP_S INPUTS [INPUTS...]\n", argv[0]);
    return 2;
  }
  try {
    return Probe(argc, argv);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "%s\n", error.what());
    return 2;
  }
}
