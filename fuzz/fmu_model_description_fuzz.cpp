// An FMU's modelDescription.xml (models/fmi/src/model_description.h): ReadModelDescription documents
// plant::PlantError with file:line for everything it refuses. It reads a file, so each input
// is written to a scratch file first. What it accepts must hold what it promises: a
// modelIdentifier, a guid, and every variable named once.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <string>

#include "fuzz_util.h"
#include "hiltwin/plant/plant.h"
#include "model_description.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = hiltwin::fuzz::WriteScratch("modelDescription.xml", data, size);
  try {
    const hiltwin::fmi::ModelDescription md = hiltwin::fmi::ReadModelDescription(path, "fuzz.fmu");
    std::set<std::string> names;
    for (const auto& variable : md.variables) {
      if (!names.insert(variable.name).second || md.Find(variable.name) == nullptr) {
        std::fprintf(stderr, "FINDING: variable '%s' accepted twice or not found\n",
                     variable.name.c_str());
        std::abort();
      }
    }
  } catch (const hiltwin::plant::PlantError&) {
  }
  HILTWIN_FUZZ_UNDOCUMENTED("ReadModelDescription")
  return 0;
}
