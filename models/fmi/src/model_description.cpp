// libxml2 parsing of modelDescription.xml. Messages give "FMU: modelDescription.xml:LINE" so a
// user finds the spot inside the archive, whose unpacked path is a temporary folder.
#include "model_description.h"

#include <libxml/parser.h>
#include <libxml/tree.h>

#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <system_error>
#include <utility>

#include "hiltwin/plant/plant.h"

namespace hiltwin::fmi {
namespace {

using plant::PlantError;

struct DocFreer {
  void operator()(xmlDoc* doc) const noexcept { xmlFreeDoc(doc); }
};
struct CtxtFreer {
  void operator()(xmlParserCtxt* ctxt) const noexcept { xmlFreeParserCtxt(ctxt); }
};
using DocPtr = std::unique_ptr<xmlDoc, DocFreer>;

constexpr const char* kFixIt = "fix the file or export the FMU again";

// Where a message points: "lag.fmu: modelDescription.xml:12".
struct Where {
  std::string fmu;
  [[nodiscard]] std::string At(const xmlNode* node) const {
    return fmu + ": modelDescription.xml:" + std::to_string(xmlGetLineNo(node));
  }
};

bool Named(const xmlNode* node, const char* name) {
  return node->type == XML_ELEMENT_NODE &&
         xmlStrcmp(node->name, reinterpret_cast<const xmlChar*>(name)) == 0;
}

std::optional<std::string> Attribute(const xmlNode* node, const char* name) {
  xmlChar* value = xmlGetProp(node, reinterpret_cast<const xmlChar*>(name));
  if (value == nullptr) {
    return std::nullopt;
  }
  std::string text(reinterpret_cast<const char*>(value));
  xmlFree(value);
  return text;
}

std::string RequiredAttribute(const xmlNode* node, const char* name, const Where& where) {
  std::optional<std::string> value = Attribute(node, name);
  if (!value || value->empty()) {
    throw PlantError(where.At(node) + ": <" + reinterpret_cast<const char*>(node->name) +
                     "> has no " + name + " attribute, which FMI 2.0 requires: export the " +
                     "FMU again, or report it to the tool that made it");
  }
  return *value;
}

const xmlNode* FirstChild(const xmlNode* parent, const char* name) {
  for (const xmlNode* child = parent->children; child != nullptr; child = child->next) {
    if (Named(child, name)) {
      return child;
    }
  }
  return nullptr;
}

struct FirstError {
  bool seen = false;
  int line = 0;
  std::string message;
};

void RecordFirstError(void* user_data, xmlError* error) {
  auto* ctxt = static_cast<xmlParserCtxt*>(user_data);
  auto* first = ctxt != nullptr ? static_cast<FirstError*>(ctxt->_private) : nullptr;
  if (first == nullptr || first->seen || error == nullptr || error->level < XML_ERR_ERROR) {
    return;
  }
  first->seen = true;
  first->line = error->line;
  first->message = error->message != nullptr ? error->message : "";
}

DocPtr Parse(const std::filesystem::path& xml_file, const Where& where) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(xml_file, error)) {
    throw PlantError(where.fmu + ": no modelDescription.xml at the top of the archive; every " +
                     "FMU has one: this is not an FMU, or it was zipped with an extra folder " +
                     "level (zip the FMU's contents, not the folder)");
  }
  std::unique_ptr<xmlParserCtxt, CtxtFreer> ctxt(xmlNewParserCtxt());
  if (!ctxt) {
    throw PlantError("out of memory reading " + where.fmu + "'s modelDescription.xml");
  }
  // The first error is the one to show: libxml2 goes on after it and its last error is often
  // a consequence ("Premature end of data"). serror gets every error, with the context as
  // its user data.
  FirstError first;
  ctxt->_private = &first;
  ctxt->sax->serror = &RecordFirstError;
  // NONET: an FMU cannot make hiltwin fetch anything; NOERROR/NOWARNING: the error goes into
  // our message instead of libxml2 printing it.
  DocPtr doc(xmlCtxtReadFile(ctxt.get(), xml_file.c_str(), nullptr,
                             XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING));
  if (!doc || ctxt->wellFormed == 0) {
    const xmlError* last = xmlCtxtGetLastError(ctxt.get());
    std::string why = first.seen                                    ? first.message
                      : last != nullptr && last->message != nullptr ? last->message
                                                                    : "unreadable";
    while (!why.empty() && (why.back() == '\n' || why.back() == ' ')) {
      why.pop_back();
    }
    const int line = first.seen ? first.line : last != nullptr ? last->line : 0;
    throw PlantError(where.fmu + ": modelDescription.xml:" + std::to_string(line) +
                     ": not well-formed XML (" + why + "): fix the file or export the FMU again");
  }
  return doc;
}

void CheckRoot(const xmlNode* root, const Where& where, ModelDescription& md) {
  if (root == nullptr || !Named(root, "fmiModelDescription")) {
    throw PlantError(where.fmu + ": modelDescription.xml: the root element is not " +
                     "<fmiModelDescription>: this is not an FMU's model description");
  }
  md.fmi_version = Attribute(root, "fmiVersion").value_or("");
  if (md.fmi_version != "2.0") {
    throw PlantError(where.At(root) + ": fmiVersion is \"" + md.fmi_version + "\"; hiltwin " +
                     "runs FMI 2.0 only: export the model as an FMI 2.0 co-simulation FMU");
  }
  md.guid = RequiredAttribute(root, "guid", where);
  md.model_name = Attribute(root, "modelName").value_or("");
  md.generation_tool = Attribute(root, "generationTool").value_or("");
}

void ReadCoSimulation(const xmlNode* root, const Where& where, ModelDescription& md) {
  const xmlNode* cs = FirstChild(root, "CoSimulation");
  if (cs == nullptr) {
    const bool me = FirstChild(root, "ModelExchange") != nullptr;
    throw PlantError(where.At(root) + ": " +
                     (me ? "a ModelExchange-only FMU (it has <ModelExchange> but no "
                           "<CoSimulation>); hiltwin runs co-simulation FMUs, which bring "
                           "their own solver: export the model for co-simulation"
                         : "no <CoSimulation> element: export the model as an FMI 2.0 "
                           "co-simulation FMU"));
  }
  md.model_identifier = RequiredAttribute(cs, "modelIdentifier", where);
}

void ReadDefaultExperiment(const xmlNode* root, const Where& where, ModelDescription& md) {
  const xmlNode* experiment = FirstChild(root, "DefaultExperiment");
  if (experiment == nullptr) {
    return;
  }
  if (const std::optional<std::string> step = Attribute(experiment, "stepSize")) {
    char* end = nullptr;
    const double value = std::strtod(step->c_str(), &end);
    if (end == step->c_str() || *end != '\0' || !(value > 0.0)) {
      throw PlantError(where.At(experiment) + ": DefaultExperiment stepSize \"" + *step +
                       "\" is not a positive number of seconds: fix or remove it");
    }
    md.default_step_s = value;
  }
}

// <TypeDefinitions><SimpleType name="Velocity"><Real unit="m/s"/>: declared type -> unit.
std::map<std::string, std::string> ReadTypeUnits(const xmlNode* root) {
  std::map<std::string, std::string> units;
  const xmlNode* types = FirstChild(root, "TypeDefinitions");
  if (types == nullptr) {
    return units;
  }
  for (const xmlNode* type = types->children; type != nullptr; type = type->next) {
    if (!Named(type, "SimpleType")) {
      continue;
    }
    const xmlNode* real = FirstChild(type, "Real");
    const std::optional<std::string> name = Attribute(type, "name");
    if (real != nullptr && name) {
      units[*name] = Attribute(real, "unit").value_or("");
    }
  }
  return units;
}

const xmlNode* TypeElement(const xmlNode* variable) {
  for (const xmlNode* child = variable->children; child != nullptr; child = child->next) {
    if (child->type == XML_ELEMENT_NODE && !Named(child, "Annotations")) {
      return child;
    }
  }
  return nullptr;
}

ScalarVariable ReadVariable(const xmlNode* node, const Where& where,
                            const std::map<std::string, std::string>& type_units) {
  ScalarVariable variable;
  variable.line = xmlGetLineNo(node);
  variable.name = RequiredAttribute(node, "name", where);
  const std::string reference = RequiredAttribute(node, "valueReference", where);
  errno = 0;
  char* end = nullptr;
  const unsigned long value = std::strtoul(reference.c_str(), &end, 10);
  if (*end != '\0' || errno != 0 || value > 0xFFFFFFFFUL || reference.front() == '-') {
    throw PlantError(where.At(node) + ": variable \"" + variable.name + "\" has valueReference \"" +
                     reference + "\", not an unsigned 32-bit number: fix the file");
  }
  variable.value_reference = static_cast<std::uint32_t>(value);
  variable.causality = Attribute(node, "causality").value_or("local");
  const xmlNode* type = TypeElement(node);
  if (type == nullptr) {
    throw PlantError(where.At(node) + ": variable \"" + variable.name + "\" has no type " +
                     "element (<Real/>, <Integer/>, ...): fix the file");
  }
  variable.type = reinterpret_cast<const char*>(type->name);
  if (variable.type == "Real") {
    variable.unit = Attribute(type, "unit").value_or("");
    const std::optional<std::string> declared = Attribute(type, "declaredType");
    if (variable.unit.empty() && declared) {
      const auto found = type_units.find(*declared);
      variable.unit = found != type_units.end() ? found->second : "";
    }
  }
  return variable;
}

void ReadVariables(const xmlNode* root, const Where& where, ModelDescription& md) {
  const xmlNode* list = FirstChild(root, "ModelVariables");
  if (list == nullptr) {
    return;  // a model without variables has no ports; the plant map says what is missing
  }
  const std::map<std::string, std::string> type_units = ReadTypeUnits(root);
  std::map<std::string, long> lines;
  for (const xmlNode* node = list->children; node != nullptr; node = node->next) {
    if (!Named(node, "ScalarVariable")) {
      continue;
    }
    ScalarVariable variable = ReadVariable(node, where, type_units);
    const auto [it, inserted] = lines.emplace(variable.name, variable.line);
    if (!inserted) {
      throw PlantError(where.At(node) + ": variable \"" + variable.name + "\" is declared " +
                       "twice (first at line " + std::to_string(it->second) + "): fix the file");
    }
    md.variables.push_back(std::move(variable));
  }
}

// A 1-based index into ModelVariables (FMI 2.0 §2.2.8: ModelStructure and a Real's derivative
// name variables so). `what` says where it stands, for messages.
std::size_t VariableIndex(std::string_view text, const std::string& what, const xmlNode* node,
                          const Where& where, const ModelDescription& md) {
  const std::string count = std::to_string(md.variables.size());
  std::size_t index = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), index);
  if (text.empty() || error != std::errc() || end != text.data() + text.size()) {
    throw PlantError(where.At(node) + ": " + what + ": \"" + std::string(text) +
                     "\" is not a variable's index (1 to " + count + "): " + kFixIt);
  }
  if (index == 0 || index > md.variables.size()) {
    throw PlantError(where.At(node) + ": " + what + " refers to variable " +
                     std::to_string(index) + ", but <ModelVariables> declares " + count +
                     " (indices count from 1): " + kFixIt);
  }
  return index - 1;
}

// Every <Unknown> of one ModelStructure list: index and dependencies within ModelVariables,
// and for <Outputs> a variable whose causality is "output".
void CheckUnknowns(const xmlNode* list, const Where& where, const ModelDescription& md) {
  const std::string list_name = reinterpret_cast<const char*>(list->name);
  for (const xmlNode* node = list->children; node != nullptr; node = node->next) {
    if (!Named(node, "Unknown")) continue;
    const std::string index_text = RequiredAttribute(node, "index", where);
    const std::string label = "<" + list_name + "> <Unknown index=\"" + index_text + "\">";
    const std::size_t index = VariableIndex(index_text, label, node, where, md);
    const ScalarVariable& variable = md.variables[index];
    if (list_name == "Outputs" && variable.causality != "output") {
      throw PlantError(where.At(node) + ": " + label + " refers to variable " +
                       std::to_string(index + 1) + " \"" + variable.name +
                       "\", whose causality is \"" + variable.causality +
                       "\", not \"output\": " + kFixIt);
    }
    const std::string dependencies = Attribute(node, "dependencies").value_or("");
    const std::string dependencies_label = label + " dependencies=\"" + dependencies + "\"";
    std::istringstream tokens(dependencies);
    for (std::string token; tokens >> token;) {
      static_cast<void>(VariableIndex(token, dependencies_label, node, where, md));
    }
  }
}

// References by index must name a declared variable: a file with dangling ones does not
// describe the binary it came with.
void CheckIndexReferences(const xmlNode* root, const Where& where, const ModelDescription& md) {
  if (const xmlNode* structure = FirstChild(root, "ModelStructure")) {
    for (const char* list : {"Outputs", "Derivatives", "InitialUnknowns"}) {
      if (const xmlNode* unknowns = FirstChild(structure, list)) CheckUnknowns(unknowns, where, md);
    }
  }
  const xmlNode* variables = FirstChild(root, "ModelVariables");
  for (const xmlNode* node = variables != nullptr ? variables->children : nullptr;
       node != nullptr; node = node->next) {
    const xmlNode* real = Named(node, "ScalarVariable") ? FirstChild(node, "Real") : nullptr;
    const std::optional<std::string> derivative =
        real != nullptr ? Attribute(real, "derivative") : std::nullopt;
    if (derivative) {
      static_cast<void>(VariableIndex(*derivative, "<Real derivative=\"" + *derivative + "\">",
                                      real, where, md));
    }
  }
}

}  // namespace

const ScalarVariable* ModelDescription::Find(std::string_view name) const noexcept {
  for (const ScalarVariable& variable : variables) {
    if (variable.name == name) {
      return &variable;
    }
  }
  return nullptr;
}

ModelDescription ReadModelDescription(const std::filesystem::path& xml_file,
                                      std::string_view fmu_name) {
  const Where where{std::string(fmu_name)};
  const DocPtr doc = Parse(xml_file, where);
  const xmlNode* root = xmlDocGetRootElement(doc.get());
  ModelDescription md;
  CheckRoot(root, where, md);
  ReadCoSimulation(root, where, md);
  ReadDefaultExperiment(root, where, md);
  ReadVariables(root, where, md);
  CheckIndexReferences(root, where, md);
  return md;
}

}  // namespace hiltwin::fmi
