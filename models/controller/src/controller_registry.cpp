// PLACEHOLDER of branch sim37: a minimal registry so the 20-sim and FMU controllers can be
// tested before helper A's controller_registry.cpp is merged. At merge, take helper A's file.
#include "hiltwin/controller/controller_registry.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <utility>

namespace hiltwin::controller {
namespace {

std::map<std::string, ControllerEntry>& Entries() {
  static std::map<std::string, ControllerEntry> entries;
  return entries;
}
std::map<std::string, ControllerKind>& Kinds() {
  static std::map<std::string, ControllerKind> kinds;
  return kinds;
}

}  // namespace

bool RegisterController(ControllerEntry entry) {
  const std::string name = entry.name;
  if (!Entries().emplace(name, std::move(entry)).second) {
    std::fprintf(stderr, "hiltwin: two controllers are registered as '%s'\n", name.c_str());
    std::abort();
  }
  return true;
}

bool RegisterControllerKind(ControllerKind kind) {
  const std::string prefix = kind.prefix;
  if (!Kinds().emplace(prefix, std::move(kind)).second) {
    std::fprintf(stderr, "hiltwin: two controller kinds use '%s:'\n", prefix.c_str());
    std::abort();
  }
  return true;
}

const ControllerEntry* FindController(const std::string& name) {
  const auto it = Entries().find(name);
  return it == Entries().end() ? nullptr : &it->second;
}

std::vector<const ControllerEntry*> RegisteredControllers() {
  std::vector<const ControllerEntry*> out;
  for (const auto& [name, entry] : Entries()) out.push_back(&entry);
  return out;
}

std::vector<const ControllerKind*> RegisteredControllerKinds() {
  std::vector<const ControllerKind*> out;
  for (const auto& [prefix, kind] : Kinds()) out.push_back(&kind);
  return out;
}

std::unique_ptr<Controller> MakeController(const std::string& spec,
                                           const ControllerOptions& options) {
  const std::size_t colon = spec.find(':');
  if (colon != std::string::npos) {
    const auto it = Kinds().find(spec.substr(0, colon));
    if (it != Kinds().end()) return it->second.load(spec.substr(colon + 1), options);
  }
  if (const ControllerEntry* entry = FindController(spec)) return entry->make(options);
  throw ControllerError("--controller " + spec + ": no such controller");
}

}  // namespace hiltwin::controller
