// load_deployment() and cyclone_config(): placement, validation errors at file:line:column,
// and generated Cyclone XML that Cyclone itself accepts.
#include <gtest/gtest.h>

#include <dds/dds.h>

#include <filesystem>
#include <fstream>

#include "avs/deploy/deployment.hpp"
#include "avs/msg/type_support.hpp"
#include "avs/runtime/component.hpp"

namespace avs::deploy {
namespace {

namespace fs = std::filesystem;
using String = std_msgs_msg_dds__String_;

void register_fake_components() {
  static const bool done = [] {
    auto& registry = runtime::ComponentRegistry::instance();
    auto factory = [](runtime::ComponentContext& ctx) {
      return std::make_unique<runtime::Component>(ctx);
    };
    runtime::ComponentSpec talker;
    talker.type = "dep_talker";
    talker.publishes = {runtime::port<String>("chatter", "/chatter")};
    registry.add(talker, factory);
    runtime::ComponentSpec listener;
    listener.type = "dep_listener";
    listener.subscribes = {runtime::port<String>("chatter", "/chatter")};
    registry.add(listener, factory);
    return true;
  }();
  (void)done;
}

class DeploymentTest : public ::testing::Test {
 protected:
  void SetUp() override {
    register_fake_components();
    dir_ = fs::temp_directory_path() /
           ("avs_deploy_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    write("graph.yaml",
          "containers:\n"
          "  - name: talkers\n"
          "    components:\n"
          "      - {type: dep_talker, name: talker}\n"
          "  - name: listeners\n"
          "    components:\n"
          "      - {type: dep_listener, name: listener}\n");
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }

  /// Loads `text` as deploy.yaml; expects exactly one error and returns it.
  std::string single_error(const std::string& text) {
    const std::string file = write("deploy.yaml", text);
    LoadResult r = load_deployment(file, {});
    EXPECT_EQ(r.errors.size(), 1u);
    if (r.errors.empty()) return "";
    for (const auto& e : r.errors) std::cerr << "  " << e.str() << "\n";
    std::string s = r.errors.front().str();
    return s.substr(s.find("deploy.yaml"));
  }

  fs::path dir_;
};

const char* kTwoHosts =
    "graph: graph.yaml\n"
    "domain_id: 177\n"
    "partition: lab_1\n"
    "discovery: {multicast: false, lease_duration_s: 2}\n"
    "hosts:\n"
    "  - name: A\n"
    "    address: 127.0.0.1\n"
    "    containers: [talkers]\n"
    "  - name: B\n"
    "    address: 127.0.0.2\n"
    "    containers: [listeners]\n";

TEST_F(DeploymentTest, LoadsPlacementAndSettings) {
  const std::string file = write("deploy.yaml", kTwoHosts);
  EXPECT_TRUE(is_deployment_file(file));
  EXPECT_FALSE(is_deployment_file((dir_ / "graph.yaml").string()));
  LoadResult r = load_deployment(file, {});
  for (const auto& e : r.errors) ADD_FAILURE() << e.str();
  ASSERT_TRUE(r.ok());
  const Deployment& d = *r.deployment;
  EXPECT_EQ(d.domain_id, 177);
  EXPECT_EQ(d.partition, "lab_1");
  EXPECT_FALSE(d.discovery.multicast);
  EXPECT_DOUBLE_EQ(d.discovery.lease_duration_s, 2.0);
  ASSERT_EQ(d.hosts.size(), 2u);
  EXPECT_EQ(d.host_of("talkers")->name, "A");
  EXPECT_EQ(d.host_of("listeners")->name, "B");
  EXPECT_EQ(d.graph.containers.size(), 2u);
}

TEST_F(DeploymentTest, UnicastConfigHasPeersIndicesAndBuffers) {
  LoadResult r = load_deployment(write("deploy.yaml", kTwoHosts), {});
  ASSERT_TRUE(r.ok());
  const std::string xml = cyclone_config(*r.deployment, r.deployment->hosts[0], "talkers");
  EXPECT_NE(xml.find("<NetworkInterface address=\"127.0.0.1\"/>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<AllowMulticast>false</AllowMulticast>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<ParticipantIndex>auto</ParticipantIndex>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<Peer address=\"127.0.0.1\"/><Peer address=\"127.0.0.2\"/>"),
            std::string::npos)
      << xml;
  EXPECT_NE(xml.find("<LeaseDuration>2s</LeaseDuration>"), std::string::npos) << xml;
  // 256 KiB x 1 kHz x 32 ms = 8 388 608 B of writer cache and receive buffer.
  EXPECT_EQ(r.deployment->transport.window_bytes(), 8388608u);
  EXPECT_NE(xml.find("<WhcHigh>8388608B</WhcHigh>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<SocketReceiveBufferSize min=\"default\" max=\"8388608B\"/>"),
            std::string::npos)
      << xml;
  EXPECT_EQ(xml.find("<Security>"), std::string::npos) << xml;
}

TEST_F(DeploymentTest, CycloneAcceptsTheGeneratedConfig) {
  // Multicast off on loopback (always present); Cyclone rejects unknown elements and values.
  LoadResult r = load_deployment(write("deploy.yaml", kTwoHosts), {});
  ASSERT_TRUE(r.ok());
  Deployment d = *r.deployment;
  d.hosts[0].address.clear();
  d.hosts[0].interface = "lo";
  for (bool multicast : {false, true}) {
    d.discovery.multicast = multicast;
    d.transport.receive_buffer_bytes = multicast ? 0 : 262144;  // Sizing/ReceiveBufferSize too
    const std::string xml = cyclone_config(d, d.hosts[0], "talkers");
    const dds_domainid_t id = multicast ? 188 : 189;
    const dds_entity_t domain = dds_create_domain(id, xml.c_str());
    ASSERT_GT(domain, 0) << dds_strretcode(domain) << "\n" << xml;
    const dds_entity_t participant = dds_create_participant(id, nullptr, nullptr);
    EXPECT_GT(participant, 0) << dds_strretcode(participant) << "\n" << xml;
    dds_delete(domain);
  }
}

TEST_F(DeploymentTest, ArgsReachTheGraphAndOverridesWin) {
  write("graph.yaml",
        "args: {topic: {default: /chatter}}\n"
        "containers:\n"
        "  - name: talkers\n"
        "    components:\n"
        "      - {type: dep_talker, name: talker, remap: {chatter: $(arg topic)}}\n");
  const std::string file = write("deploy.yaml",
                                 "graph: graph.yaml\nargs: {topic: /a}\nhosts:\n"
                                 "  - {name: one, containers: [talkers]}\n");
  LoadResult r = load_deployment(file, {{"topic", "/b"}});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.deployment->graph.args.at("topic"), "/b");
  EXPECT_EQ(r.deployment->graph_args.at("topic"), "/b");
}

TEST_F(DeploymentTest, UnknownContainerSuggestsTheClosest) {
  const std::string e = single_error(
      "graph: graph.yaml\nhosts:\n  - name: A\n    containers: [talkers, listenrs]\n"
      "  - {name: B, containers: [listeners]}\n");
  EXPECT_EQ(e.rfind("deploy.yaml:4:27: error: container 'listenrs' is not in graph", 0), 0u) << e;
  EXPECT_NE(e.find("did you mean 'listeners'"), std::string::npos) << e;
}

TEST_F(DeploymentTest, ContainerPlacedTwice) {
  const std::string e = single_error(
      "graph: graph.yaml\nhosts:\n  - {name: A, containers: [talkers, listeners]}\n"
      "  - {name: B, containers: [talkers]}\n");
  EXPECT_EQ(e.rfind("deploy.yaml:4:28: error: container 'talkers' is placed twice; first at", 0),
            0u)
      << e;
}

TEST_F(DeploymentTest, UnplacedContainer) {
  const std::string e =
      single_error("graph: graph.yaml\nhosts:\n  - {name: A, containers: [talkers]}\n");
  EXPECT_EQ(e.rfind("deploy.yaml:1:8: error: graph container 'listeners'", 0), 0u) << e;
  EXPECT_NE(e.find("is placed on no host"), std::string::npos) << e;
}

TEST_F(DeploymentTest, BadAddress) {
  const std::string e = single_error(
      "graph: graph.yaml\nhosts:\n  - {name: A, address: 10.0.0.300, containers: [talkers, "
      "listeners]}\n");
  EXPECT_EQ(e,
            "deploy.yaml:3:24: error: host 'A' 'address': '10.0.0.300' is not an IPv4 "
            "address like 10.0.0.2");
}

TEST_F(DeploymentTest, UnicastNeedsAddresses) {
  const std::string e = single_error(
      "graph: graph.yaml\ndiscovery: {multicast: false}\nhosts:\n"
      "  - {name: A, address: 10.0.0.1, containers: [talkers]}\n"
      "  - {name: B, containers: [listeners]}\n");
  EXPECT_EQ(e.rfind("deploy.yaml:5:5: error: host 'B': 'address' is required with discovery "
                    "multicast: false",
                    0),
            0u)
      << e;
}

TEST_F(DeploymentTest, UnknownKeyAndBadValues) {
  const std::string file = write("deploy.yaml",
                                 "graph: graph.yaml\n"
                                 "domain_id: 400\n"
                                 "partition: 'lab*'\n"
                                 "discovery: {multicast: yes}\n"
                                 "hostz: []\n"
                                 "hosts:\n"
                                 "  - {name: 1A, containers: [talkers, listeners]}\n");
  LoadResult r = load_deployment(file, {});
  ASSERT_EQ(r.errors.size(), 5u);
  const auto where = [&](std::size_t i) {
    return std::to_string(r.errors[i].where.line) + ":" + std::to_string(r.errors[i].where.column);
  };
  EXPECT_EQ(where(0), "2:12") << r.errors[0].str();  // domain_id out of range
  EXPECT_EQ(where(1), "3:12") << r.errors[1].str();  // wildcard in partition
  EXPECT_EQ(where(2), "4:24") << r.errors[2].str();  // yes is not a bool here
  EXPECT_EQ(where(3), "5:1") << r.errors[3].str();   // unknown key
  EXPECT_NE(r.errors[3].str().find("did you mean 'hosts'"), std::string::npos) << r.errors[3].str();
  EXPECT_EQ(where(4), "7:12") << r.errors[4].str();  // host name starts with a digit
}

TEST_F(DeploymentTest, ReceiveBufferSizeIsCheckedAndReachesCyclone) {
  // Below Cyclone's largest message chunk twice over: refused at its value, with the bound.
  const std::string e =
      single_error(std::string(kTwoHosts) + "transport: {receive_buffer_bytes: 1000}\n");
  EXPECT_NE(e.find("deploy.yaml:12:"), std::string::npos) << e;
  EXPECT_NE(e.find("below 262144"), std::string::npos) << e;
  LoadResult r = load_deployment(
      write("deploy.yaml", std::string(kTwoHosts) + "transport: {receive_buffer_bytes: 524288}\n"),
      {});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.deployment->transport.receive_buffer_bytes, 524288u);
  const std::string xml = cyclone_config(*r.deployment, r.deployment->hosts[0], "talkers");
  EXPECT_NE(xml.find("<Sizing><ReceiveBufferSize>524288B</ReceiveBufferSize></Sizing>"),
            std::string::npos)
      << xml;
  // Not given: Cyclone's own default, no element.
  LoadResult plain = load_deployment(write("deploy.yaml", kTwoHosts), {});
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(
      cyclone_config(*plain.deployment, plain.deployment->hosts[0], "talkers").find("<Sizing>"),
      std::string::npos);
}

TEST_F(DeploymentTest, GraphErrorsAreReportedWithTheGraphFile) {
  write("graph.yaml",
        "containers:\n  - name: talkers\n    components:\n      - {type: nope, name: x}\n");
  const std::string file =
      write("deploy.yaml", "graph: graph.yaml\nhosts:\n  - {name: A, containers: [talkers]}\n");
  LoadResult r = load_deployment(file, {});
  ASSERT_FALSE(r.errors.empty());
  EXPECT_NE(r.errors.back().str().find("graph.yaml:4:"), std::string::npos)
      << r.errors.back().str();
}

TEST_F(DeploymentTest, SecurityNeedsTheFolderOfSecurityInit) {
  const std::string e = single_error(
      "graph: graph.yaml\nsecurity: {enabled: true, dir: nowhere}\n"
      "hosts:\n  - {name: A, containers: [talkers, listeners]}\n");
  EXPECT_EQ(e.rfind("deploy.yaml:2:32: error: security 'dir': no CA in", 0), 0u) << e;
  EXPECT_NE(e.find("avs security init nowhere"), std::string::npos) << e;
}

TEST_F(DeploymentTest, SecurityConfigNamesTheParticipantsIdentity) {
  fs::create_directories(dir_ / "sec");
  std::ofstream(dir_ / "sec" / "ca_cert.pem") << "x";
  LoadResult r = load_deployment(write("deploy.yaml",
                                       "graph: graph.yaml\nsecurity: {enabled: true, dir: sec}\n"
                                       "hosts:\n  - {name: A, containers: [talkers, listeners]}\n"),
                                 {});
  ASSERT_TRUE(r.ok());
  const std::string xml = cyclone_config(*r.deployment, r.deployment->hosts[0], "talkers");
  const std::string sec = (dir_ / "sec").string();
  EXPECT_NE(xml.find("<IdentityCertificate>file:" + sec + "/identities/talkers/cert.pem<"),
            std::string::npos)
      << xml;
  EXPECT_NE(xml.find("<Governance>file:" + sec + "/governance.p7s<"), std::string::npos) << xml;
}

TEST_F(DeploymentTest, HostWithoutContainersIsAUnicastPeer) {
  // A foreign subscriber's machine: no containers, but in every host's Peers.
  LoadResult r = load_deployment(
      write("deploy.yaml",
            std::string(kTwoHosts) + "  - {name: ros_pc, address: 127.0.0.3, containers: []}\n"),
      {});
  for (const auto& e : r.errors) ADD_FAILURE() << e.str();
  ASSERT_TRUE(r.ok());
  const std::string xml = cyclone_config(*r.deployment, r.deployment->hosts[0], "talkers");
  EXPECT_NE(xml.find("<Peer address=\"127.0.0.3\"/>"), std::string::npos) << xml;
}

}  // namespace
}  // namespace avs::deploy
