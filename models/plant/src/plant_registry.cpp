// Plants by name (plant_registry.h).
#include "hiltwin/plant/plant_registry.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>

namespace hiltwin::plant {
namespace {

// A function-local static: registrations run during static initialisation of other
// translation units, in no defined order, so the map must exist before the first of them.
std::map<std::string, PlantEntry>& Registry() {
  static std::map<std::string, PlantEntry> entries;
  return entries;
}

}  // namespace

bool RegisterPlant(PlantEntry entry) {
  auto& entries = Registry();
  if (const auto it = entries.find(entry.name); it != entries.end()) {
    // Two plants under one name is a build mistake; nothing could choose between them.
    std::fprintf(stderr, "hiltwin: two plants are registered as '%s' (%s; %s): rename one\n",
                 entry.name.c_str(), it->second.description.c_str(), entry.description.c_str());
    std::abort();
  }
  std::string name = entry.name;
  entries.emplace(std::move(name), std::move(entry));
  return true;
}

const PlantEntry* FindPlant(const std::string& name) {
  const auto& entries = Registry();
  const auto it = entries.find(name);
  return it == entries.end() ? nullptr : &it->second;
}

std::vector<const PlantEntry*> RegisteredPlants() {
  std::vector<const PlantEntry*> out;
  for (const auto& [name, entry] : Registry()) out.push_back(&entry);
  return out;  // std::map iterates in name order
}

}  // namespace hiltwin::plant
