#include "dds_common.h"

#include <cstdlib>
#include <stdexcept>

namespace hiltwin::telemetry::dds {

void CheckDomain(std::uint32_t domain, const std::string& flag) {
  if (domain > kMaxDomain) {
    throw std::invalid_argument(flag + ": DDS domain " + std::to_string(domain) +
                                " is out of range; use 0.." + std::to_string(kMaxDomain) +
                                " (the range of ROS_DOMAIN_ID)");
  }
}

Entity CreateParticipant(std::uint32_t domain, const std::string& flag) {
  CheckDomain(domain, flag);
  const dds_entity_t participant =
      dds_create_participant(static_cast<dds_domainid_t>(domain), nullptr, nullptr);
  if (participant < 0) {
    // Read once, on the control thread, before any helper thread of ours exists.
    const char* uri = std::getenv("CYCLONEDDS_URI");  // NOLINT(concurrency-mt-unsafe)
    throw std::runtime_error(
        flag + ": Cyclone DDS could not join domain " + std::to_string(domain) + " (" +
        dds_strretcode(participant) + ") with CYCLONEDDS_URI " +
        (uri != nullptr ? std::string("'") + uri + "'" : std::string("unset (its defaults)")) +
        "; fix the configuration it names (Cyclone printed the reason above), or on one machine "
        "without multicast (a container, a laptop off the network) set "
        "CYCLONEDDS_URI=file://<hiltwin>/config/cyclonedds-loopback.xml");
  }
  return Entity(participant);
}

dds_entity_t Check(dds_entity_t rc, const std::string& what) {
  if (rc < 0) throw std::runtime_error(what + ": " + dds_strretcode(rc));
  return rc;
}

QosPtr MakeQos(std::int32_t depth, Durability durability) {
  QosPtr qos(dds_create_qos(), &dds_delete_qos);
  dds_qset_reliability(qos.get(), DDS_RELIABILITY_RELIABLE, 0);
  dds_qset_history(qos.get(), DDS_HISTORY_KEEP_LAST, depth);
  dds_qset_durability(qos.get(), durability == Durability::kTransientLocal
                                     ? DDS_DURABILITY_TRANSIENT_LOCAL
                                     : DDS_DURABILITY_VOLATILE);
  return qos;
}

dds_entity_t CreateTopic(dds_entity_t participant, const dds_topic_descriptor_t* descriptor,
                         const std::string& name) {
  return Check(dds_create_topic(participant, descriptor, name.c_str(), nullptr, nullptr),
               "DDS topic " + name + " (" + descriptor->m_typename + ")");
}

std::string TopicName(const std::string& ns, const char* leaf) { return "rt/" + ns + "/" + leaf; }

dds_entity_t CreatePublicationReader(dds_entity_t participant) {
  // The macro is Cyclone's pseudo-handle, defined with a C cast in its header.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wold-style-cast"
  const dds_entity_t builtin = DDS_BUILTIN_TOPIC_DCPSPUBLICATION;
#pragma GCC diagnostic pop
  return Check(dds_create_reader(participant, builtin, nullptr, nullptr),
               "DDS reader of the built-in publication topic");
}

void SetUserData(dds_qos_t* qos, std::string_view text) {
  dds_qset_userdata(qos, text.data(), text.size());
}

std::string UserDataOf(const dds_qos_t* qos) {
  void* value = nullptr;
  std::size_t size = 0;
  if (qos == nullptr || !dds_qget_userdata(qos, &value, &size) || value == nullptr) return {};
  std::string text(static_cast<const char*>(value), size);
  dds_free(value);  // dds_qget_userdata hands over a copy
  return text;
}

}  // namespace hiltwin::telemetry::dds
