// avs security init DIR --deployment FILE: a DDS Security setup for a deployment, made with
// the openssl command: a CA (identity and permissions CA), one identity per participant (each
// container of the graph, plus "observer" for avs tools and the launchers' watches), and the
// governance and permissions documents signed as S/MIME (what DDS Security reads).
// Permissions follow the graph: a container may publish exactly the topics its components
// publish (so only the torque source may write /head/torque_command, only the matcher the
// poses) and read the topics they read; "observer" may read everything and write nothing.
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>

#include "avs/deploy/deployment.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/topic_name.hpp"
#include "commands.hpp"

namespace avs::cli {
namespace {

namespace fs = std::filesystem;

/// Runs `argv` (searched on PATH); throws with the command line when it fails.
void run(const std::vector<std::string>& argv) {
  std::vector<std::string> copy = argv;
  std::vector<char*> args;
  for (auto& a : copy) args.push_back(a.data());
  args.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid == 0) {
    execvp(args[0], args.data());
    std::cerr << "avs security: cannot run " << argv[0] << ": " << std::strerror(errno) << "\n";
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::string line;
    for (const auto& a : argv) line += (line.empty() ? "" : " ") + a;
    throw std::runtime_error("command failed: " + line);
  }
}

constexpr const char* kSubjectPrefix = "C=NL,O=avs,CN=";

void write_file(const fs::path& p, const std::string& text) {
  std::ofstream out(p);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + p.string());
}

std::string governance_xml(int domain) {
  const std::string d = domain < 0 ? "<id_range><min>0</min><max>232</max></id_range>"
                                   : "<id>" + std::to_string(domain) + "</id>";
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains>)" +
         d + R"(</domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>NONE</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
)";
}

struct Grant {
  std::string participant;
  std::set<std::string> publish, subscribe;  ///< DDS topic names or patterns
};

std::string rule(const char* kind, const std::set<std::string>& topics,
                 const std::string& partition) {
  if (topics.empty()) return "";
  std::string s = std::string("          <") + kind + ">\n            <topics>\n";
  for (const auto& t : topics) s += "              <topic>" + t + "</topic>\n";
  s += "            </topics>\n";
  // Without a <partitions> element a rule covers only the default partition.
  if (!partition.empty()) {
    s += "            <partitions><partition>" + partition + "</partition></partitions>\n";
  }
  return s + "          </" + kind + ">\n";
}

std::string permissions_xml(const std::vector<Grant>& grants, int domain,
                            const std::string& partition) {
  const std::string d = domain < 0 ? "<id_range><min>0</min><max>232</max></id_range>"
                                   : "<id>" + std::to_string(domain) + "</id>";
  std::string s = R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
)";
  for (const auto& g : grants) {
    s += "    <grant name=\"" + g.participant + "\">\n";
    s += "      <subject_name>" + std::string(kSubjectPrefix) + g.participant + "</subject_name>\n";
    s += "      <validity><not_before>2020-01-01T00:00:00</not_before>"
         "<not_after>2040-01-01T00:00:00</not_after></validity>\n";
    s += "      <allow_rule>\n        <domains>" + d + "</domains>\n";
    s += rule("publish", g.publish, partition);
    s += rule("subscribe", g.subscribe, partition);
    s += "      </allow_rule>\n      <default>DENY</default>\n    </grant>\n";
  }
  return s + "  </permissions>\n</dds>\n";
}

/// One grant per container from the graph, plus the observer.
std::vector<Grant> grants_of(const deploy::Deployment& d) {
  std::vector<Grant> out;
  const auto& registry = runtime::ComponentRegistry::instance();
  for (const auto& c : d.graph.containers) {
    Grant g{c.name,
            // Every container counts its writers for recorders (/avs/writer_counts) and, in
            // lockstep, reads what recorders have (/avs/recorder_progress, docs/bag.md).
            {"rt/diagnostics", "rt/clock", "rt/parameter_events", "ros_discovery_info",
             "rt/avs/writer_counts"},
            {"rt/clock", "rt/avs/recorder_progress"}};
    for (const auto& comp : c.components) {
      // Each component is a ROS 2 node answering its parameter services (docs/operate.md).
      const std::string node = runtime::resolve_topic_name(d.graph.ns, comp.name);
      g.publish.insert("rr" + node + "/*");
      g.subscribe.insert("rq" + node + "/*");
      const runtime::RegisteredComponent* reg = registry.find(comp.type);
      if (reg == nullptr) continue;
      for (const auto& p : reg->spec.publishes)
        g.publish.insert("rt" + graph::port_topic(d.graph, comp, p));
      for (const auto& p : reg->spec.subscribes)
        g.subscribe.insert("rt" + graph::port_topic(d.graph, comp, p));
    }
    out.push_back(std::move(g));
  }
  out.push_back(Grant{"observer", {}, {"*"}});
  return out;
}

int security_init(const std::string& dir_arg, const std::string& deployment_file,
                  const std::vector<std::string>& extra, bool force) {
  std::vector<Grant> grants;
  int domain = -1;
  std::string partition;
  if (!deployment_file.empty()) {
    // The deployment may say `security: {enabled: true, dir: DIR}` before DIR exists.
    deploy::LoadResult r =
        deploy::load_deployment(deployment_file, {}, /*check_security_files=*/false);
    for (const auto& e : r.errors) std::cerr << e.str() << "\n";
    if (!r.ok()) return 2;
    grants = grants_of(*r.deployment);
    domain = r.deployment->domain_id;
    partition = r.deployment->partition;
  } else {
    grants.push_back(Grant{"observer", {}, {"*"}});
  }
  for (const auto& name : extra) grants.push_back(Grant{name, {"*"}, {"*"}});

  const fs::path dir(dir_arg);
  if (fs::exists(dir / "ca_cert.pem") && !force) {
    std::cerr << "avs security: " << (dir / "ca_cert.pem").string()
              << " exists; use --force to make a new CA (every identity is then replaced)\n";
    return 2;
  }
  fs::create_directories(dir / "identities");
  const std::string ca_key = (dir / "ca_key.pem").string();
  const std::string ca_cert = (dir / "ca_cert.pem").string();
  run({"openssl", "ecparam", "-name", "prime256v1", "-genkey", "-noout", "-out", ca_key});
  run({"openssl", "req", "-x509", "-new", "-key", ca_key, "-sha256", "-days", "3650", "-subj",
       "/C=NL/O=avs/CN=avs DDS CA", "-out", ca_cert});
  fs::permissions(ca_key, fs::perms::owner_read | fs::perms::owner_write);
  for (const auto& g : grants) {
    const fs::path id = dir / "identities" / g.participant;
    fs::create_directories(id);
    const std::string key = (id / "key.pem").string(), csr = (id / "cert.csr").string(),
                      cert = (id / "cert.pem").string();
    run({"openssl", "ecparam", "-name", "prime256v1", "-genkey", "-noout", "-out", key});
    fs::permissions(key, fs::perms::owner_read | fs::perms::owner_write);
    run({"openssl", "req", "-new", "-key", key, "-subj", "/C=NL/O=avs/CN=" + g.participant, "-out",
         csr});
    run({"openssl", "x509", "-req", "-in", csr, "-CA", ca_cert, "-CAkey", ca_key, "-CAcreateserial",
         "-days", "3650", "-sha256", "-out", cert});
    fs::remove(csr);
  }
  write_file(dir / "governance.xml", governance_xml(domain));
  write_file(dir / "permissions.xml", permissions_xml(grants, domain, partition));
  for (const char* doc : {"governance", "permissions"}) {
    run({"openssl", "smime", "-sign", "-in", (dir / (std::string(doc) + ".xml")).string(), "-text",
         "-out", (dir / (std::string(doc) + ".p7s")).string(), "-signer", ca_cert, "-inkey",
         ca_key});
  }
  std::cout << "avs security: CA, " << grants.size() << " identities, signed governance and "
            << "permissions in " << dir.string() << "\n";
  for (const auto& g : grants) {
    std::cout << "  " << g.participant << ": publish";
    for (const auto& t : g.publish) std::cout << " " << t;
    if (g.publish.empty()) std::cout << " (nothing)";
    std::cout << "; subscribe";
    for (const auto& t : g.subscribe) std::cout << " " << t;
    std::cout << "\n";
  }
  if (deploy::security_plugin_dir().empty()) {
    std::cerr << "avs security: warning: Cyclone's security plugins (libdds_security_auth.so) "
                 "were not found in the Debian folder; participants will fail to start\n";
  }
  return 0;
}

void add_security_command(Command& app) {
  auto* cmd = app.add_subcommand("security", "DDS Security for deployments (docs/deploy.md)");
  cmd->require_subcommand(1);
  auto* init = cmd->add_subcommand(
      "init", "Create a CA, one identity per participant, signed governance and permissions");
  static std::string dir, deployment;
  static std::vector<std::string> extra;
  static bool force = false;
  init->add_option("dir", dir, "output folder")->required();
  init->add_option("--deployment", deployment,
                   "deployment YAML: one identity per graph container, permissions from the "
                   "graph's topics, its domain and partition");
  init->add_option("--participant", extra,
                   "extra identity allowed to publish and subscribe everything (repeatable)");
  init->add_flag("--force", force, "replace an existing CA in DIR");
  init->callback([] {
    try {
      exit_status() = security_init(dir, deployment, extra, force);
    } catch (const std::exception& e) {
      std::cerr << "avs security init: " << e.what() << "\n";
      exit_status() = 1;
    }
  });
}

}  // namespace

AVS_REGISTER_COMMAND(add_security_command)

}  // namespace avs::cli
