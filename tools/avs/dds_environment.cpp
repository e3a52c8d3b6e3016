#include "dds_environment.hpp"

#include <cstdlib>

#include "avs/runtime/error.hpp"
#include "command.hpp"

namespace avs::cli {

std::optional<int> environment_domain() {
  const char* env = std::getenv("AVS_DOMAIN_ID");
  if (env == nullptr || *env == '\0') return std::nullopt;
  char* end = nullptr;
  const long id = std::strtol(env, &end, 10);
  if (*end != '\0' || id < 0 || id > 232) {
    throw runtime::Error(std::string("AVS_DOMAIN_ID must be a domain id in [0, 232], got '") +
                         env + "'");
  }
  return static_cast<int>(id);
}

int domain_or_environment(int fallback) {
  return environment_domain().value_or(fallback);
}

std::string environment_partition() {
  const char* env = std::getenv("AVS_PARTITION");
  return env != nullptr ? env : "";
}

Option* add_domain_option(Command* cmd, int& domain) {
  domain = domain_or_environment(0);
  return cmd->add_option("--domain", domain, "DDS domain id (default: $AVS_DOMAIN_ID or 0)")
      ->capture_default_str()
      ->check_range(0, 232);
}

void apply_environment(graph::Graph& g) {
  if (const auto domain = environment_domain()) g.domain_id = *domain;
  g.partition = environment_partition();
}

}  // namespace avs::cli
