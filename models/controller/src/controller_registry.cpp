// Controllers by --controller SPEC (controller_registry.h).
#include "hiltwin/controller/controller_registry.h"

#include <cstdio>
#include <cstdlib>
#include <map>

namespace hiltwin::controller {
namespace {

// Function-local statics: registrations may run during static initialisation of other
// translation units, in no defined order, so the maps must exist before the first of them.
std::map<std::string, ControllerEntry>& Named() {
  static std::map<std::string, ControllerEntry> entries;
  return entries;
}

std::map<std::string, ControllerKind>& Kinds() {
  static std::map<std::string, ControllerKind> kinds;
  return kinds;
}

/// Two entries under one key is a build mistake; nothing could choose between them.
template <class Map, class Value>
void AddOnce(Map& map, const std::string& key, Value value, const char* what) {
  if (const auto it = map.find(key); it != map.end()) {
    std::fprintf(stderr, "hiltwin: two controller %s are registered as '%s' (%s; %s): rename one\n",
                 what, key.c_str(), it->second.description.c_str(), value.description.c_str());
    std::abort();
  }
  map.emplace(key, std::move(value));
}

/// "pid (the built-in ...); lib:PATH (...)": what --controller accepts.
std::string WhatExists() {
  std::string out;
  for (const auto& [name, entry] : Named()) {
    out += (out.empty() ? "" : "; ") + name + " (" + entry.description + ")";
  }
  for (const auto& [prefix, kind] : Kinds()) {
    out += (out.empty() ? "" : "; ") + prefix + ":" + kind.argument + " (" + kind.description + ")";
  }
  return out.empty() ? "none registered" : out;
}

}  // namespace

bool RegisterController(ControllerEntry entry) {
  const std::string name = entry.name;
  AddOnce(Named(), name, std::move(entry), "names");
  return true;
}

bool RegisterControllerKind(ControllerKind kind) {
  const std::string prefix = kind.prefix;
  AddOnce(Kinds(), prefix, std::move(kind), "kinds");
  return true;
}

const ControllerEntry* FindController(const std::string& name) {
  const auto it = Named().find(name);
  return it == Named().end() ? nullptr : &it->second;
}

std::vector<const ControllerEntry*> RegisteredControllers() {
  std::vector<const ControllerEntry*> out;
  for (const auto& [name, entry] : Named()) out.push_back(&entry);
  return out;  // std::map iterates in name order
}

std::vector<const ControllerKind*> RegisteredControllerKinds() {
  std::vector<const ControllerKind*> out;
  for (const auto& [prefix, kind] : Kinds()) out.push_back(&kind);
  return out;
}

std::unique_ptr<Controller> MakeController(const std::string& spec,
                                           const ControllerOptions& options) {
  if (const std::size_t colon = spec.find(':'); colon != std::string::npos) {
    const auto it = Kinds().find(spec.substr(0, colon));
    if (it != Kinds().end()) {
      const std::string path = spec.substr(colon + 1);
      if (path.empty()) {
        throw ControllerError("--controller " + spec + ": nothing after '" + it->first +
                              ":': give " + it->first + ":" + it->second.argument);
      }
      return it->second.load(path, options);
    }
  }
  if (const ControllerEntry* entry = FindController(spec)) return entry->make(options);
  throw ControllerError("--controller " + spec + ": no such controller; give one of: " +
                        WhatExists() + " (docs/controllers.md)");
}

}  // namespace hiltwin::controller
