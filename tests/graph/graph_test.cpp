// load_graph(): one test per class of bad YAML (exactly one diagnostic, at the right
// file:line:column, naming the key), plus good graphs.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "avs/graph/graph.hpp"
#include "avs/msg/type_support.hpp"
#include "avs/runtime/component.hpp"

namespace avs::graph {
namespace {

using runtime::ComponentSpec;
using runtime::ParamSpec;
using runtime::PortSpec;
using String = std_msgs_msg_dds__String_;
using Image = sensor_msgs_msg_dds__Image_;

/// Component types used by the graphs in data/: two topic types so mismatches can occur.
void register_fake_components() {
  static const bool done = [] {
    auto& registry = runtime::ComponentRegistry::instance();
    auto factory = [](runtime::ComponentContext& ctx) {
      return std::make_unique<runtime::Component>(ctx);
    };
    ComponentSpec talker;
    talker.type = "fake_talker";
    talker.parameters = {
        ParamSpec::real("rate_hz", 10.0, 0.1, 10000.0, "Hz", "publish rate"),
        ParamSpec::integer("count", 3, 0.0, 1000.0, "", "messages"),
        ParamSpec::boolean("enabled", true, "publish at all"),
        ParamSpec::string("mode", "fast", "speed", {"fast", "slow"}),
        ParamSpec::real_list("gains", {1.0, 2.0, 3.0}, "", "gains"),
        ParamSpec::string("label", "", "text"),
    };
    talker.publishes = {runtime::port<String>("chatter", "chatter")};
    registry.add(talker, factory);

    ComponentSpec listener;
    listener.type = "fake_listener";
    listener.parameters = {ParamSpec::string("label", "", "text")};
    listener.subscribes = {runtime::port<String>("chatter", "chatter")};
    registry.add(listener, factory);

    ComponentSpec camera;
    camera.type = "fake_camera";
    camera.parameters = {ParamSpec::real("exposure_us", 100.0, 1.0, 1e6, "us", "exposure")};
    camera.publishes = {
        runtime::port<Image>("image", "image", *runtime::QosProfile::named("sensor_data"))};
    registry.add(camera, factory);

    ComponentSpec viewer;
    viewer.type = "fake_viewer";
    viewer.subscribes = {runtime::port<Image>("image", "image")};
    registry.add(viewer, factory);
    return true;
  }();
  (void)done;
}

std::string data(const std::string& relative) {
  return std::string(AVS_GRAPH_TEST_DATA) + "/" + relative;
}

class GraphTest : public ::testing::Test {
 protected:
  void SetUp() override { register_fake_components(); }
};

std::string all_errors(const LoadResult& result) {
  std::string out;
  for (const auto& d : result.errors) out += d.str() + "\n";
  return out;
}

/// Loads data/bad/<name> and checks there is exactly one error, at `file:line:column`
/// (file defaults to the loaded one), whose message contains every one of `words`.
void expect_one_error(const std::string& name, int line, int column,
                      const std::vector<std::string>& words,
                      const std::map<std::string, std::string>& args = {},
                      const std::string& file_with_error = "") {
  const std::string file = data("bad/" + name);
  const LoadResult result = load_graph(file, args);
  EXPECT_FALSE(result.ok());
  EXPECT_FALSE(result.graph.has_value());
  ASSERT_EQ(result.errors.size(), 1u) << all_errors(result);
  const Diagnostic& d = result.errors.front();
  const std::string expected_file = file_with_error.empty() ? file : data("bad/" + file_with_error);
  EXPECT_EQ(d.where.file, expected_file);
  EXPECT_EQ(d.where.line, line) << d.str();
  EXPECT_EQ(d.where.column, column) << d.str();
  for (const auto& w : words)
    EXPECT_NE(d.message.find(w), std::string::npos) << d.str() << "\nlacks: " << w;
  // One line, in the "file:line:column: error: message" shape.
  EXPECT_EQ(d.str().find('\n'), std::string::npos);
  EXPECT_EQ(d.str().rfind(expected_file + ":" + std::to_string(line) + ":" +
                              std::to_string(column) + ": error: ",
                          0),
            0u);
}

const ComponentInstance& component(const Graph& g, const std::string& name) {
  for (const auto& c : g.containers) {
    for (const auto& i : c.components) {
      if (i.name == name) return i;
    }
  }
  throw std::runtime_error("no component " + name);
}

// ---- bad graphs: one class each ------------------------------------------------------

TEST_F(GraphTest, YamlSyntaxError) {
  expect_one_error("yaml_syntax.yaml", 5, 21, {"YAML syntax error: illegal map value"});
}
TEST_F(GraphTest, UnknownTopLevelKey) {
  expect_one_error("unknown_top_key.yaml", 5, 1, {"unknown key 'containerz'", "'containers'"});
}
TEST_F(GraphTest, UnknownContainerKey) {
  expect_one_error("unknown_container_key.yaml", 3, 5,
                   {"container", "unknown key 'executer'", "did you mean 'executor'"});
}
TEST_F(GraphTest, UnknownComponentKey) {
  expect_one_error("unknown_component_key.yaml", 6, 9,
                   {"component", "unknown key 'params'", "did you mean 'parameters'"});
}
TEST_F(GraphTest, MissingType) {
  expect_one_error("missing_type.yaml", 4, 9,
                   {"component 'talker'", "missing required key 'type'"});
}
TEST_F(GraphTest, MissingName) {
  expect_one_error("missing_name.yaml", 4, 9, {"missing required key 'name'"});
}
TEST_F(GraphTest, MissingContainers) {
  expect_one_error("missing_containers.yaml", 1, 1, {"missing required key 'containers'"});
}
TEST_F(GraphTest, UnknownComponentType) {
  expect_one_error("unknown_type.yaml", 4, 15,
                   {"'type'", "unknown component type 'fake_talkr'", "did you mean 'fake_talker'",
                    "known types:"});
}
TEST_F(GraphTest, UnknownParameterSuggestsClosest) {
  expect_one_error("unknown_parameter.yaml", 8, 11,
                   {"unknown parameter 'rate_hzz'", "did you mean 'rate_hz'"});
}
TEST_F(GraphTest, WrongParameterType) {
  expect_one_error("wrong_type.yaml", 6, 29,
                   {"parameter 'count'", "expected an integer in [0, 1000], got '2.5'"});
}
TEST_F(GraphTest, OutOfRangeParameter) {
  expect_one_error("out_of_range.yaml", 7, 20,
                   {"parameter 'rate_hz'", "expected a number in [0.1, 10000] Hz, got 0"});
}
TEST_F(GraphTest, StringNotInChoices) {
  expect_one_error("bad_choice.yaml", 6, 28,
                   {"parameter 'mode'", "expected one of 'fast', 'slow', got 'medium'"});
}
TEST_F(GraphTest, BoolOnlyTrueOrFalse) {
  expect_one_error("bad_bool.yaml", 6, 31,
                   {"parameter 'enabled'", "expected true or false, got 'yes'"});
}
TEST_F(GraphTest, ListWithNonNumber) {
  expect_one_error("bad_list.yaml", 6, 33,
                   {"parameter 'gains'", "expected a list of numbers", "'two' at index 1"});
}
TEST_F(GraphTest, UnknownRemapPort) {
  expect_one_error("unknown_remap_port.yaml", 6, 17,
                   {"'remap'", "unknown port 'chater'", "did you mean 'chatter'"});
}
TEST_F(GraphTest, UnknownQosPort) {
  expect_one_error("unknown_qos_port.yaml", 7, 11, {"'qos'", "unknown port 'image'"});
}
TEST_F(GraphTest, BadQosProfileName) {
  expect_one_error("bad_qos_profile.yaml", 6, 24,
                   {"qos 'chatter'", "unknown QoS profile 'sensor'", "'sensor_data'"});
}
TEST_F(GraphTest, BadQosPolicyValue) {
  expect_one_error("bad_qos_value.yaml", 6, 38,
                   {"'reliability'", "expected one of 'reliable', 'best_effort', got 'sometimes'"});
}
TEST_F(GraphTest, BadTopicName) {
  expect_one_error("bad_topic_name.yaml", 6, 26, {"remap 'chatter'", "'/chat//ter'", "'//'"});
}
TEST_F(GraphTest, TwoPublishersWithDifferentTypes) {
  expect_one_error("publisher_type_conflict.yaml", 8, 24,
                   {"two publishers", "'/chatter'", "sensor_msgs/msg/Image", "std_msgs/msg/String",
                    "component 'talker'"});
}
TEST_F(GraphTest, SubscriberTypeDiffersFromPublisher) {
  expect_one_error("subscriber_type_mismatch.yaml", 11, 26,
                   {"component 'listener' port 'chatter' subscribes to '/robot/image' as "
                    "std_msgs/msg/String",
                    "component 'camera' port 'image' publishes '/robot/image' as "
                    "sensor_msgs/msg/Image"});
}
TEST_F(GraphTest, IncompatibleQosAcrossContainers) {
  expect_one_error("qos_incompatible.yaml", 8, 15,
                   {"incompatible QoS", "component 'viewer' port 'image'", "container 'display'",
                    "component 'camera'", "a reliable reader needs a reliable writer"});
}
TEST_F(GraphTest, MissingIncludeFile) {
  expect_one_error("missing_include.yaml", 2, 11,
                   {"include 'file'", "'sub/does_not_exist.yaml' not found"});
}
TEST_F(GraphTest, IncludeCycle) {
  expect_one_error("include_cycle.yaml", 3, 11,
                   {"include cycle include_cycle.yaml -> cycle_b.yaml -> include_cycle.yaml"}, {},
                   "sub/cycle_b.yaml");
}
TEST_F(GraphTest, IncludedClockMustMatch) {
  expect_one_error("include_clock_mismatch.yaml", 2, 1, {"'clock'", "differs"}, {},
                   "sub/wall_clock.yaml");
}
TEST_F(GraphTest, IncludeGivesUndeclaredArg) {
  expect_one_error("include_undeclared_arg.yaml", 3, 18, {"argument 'y'", "not declared"});
}
TEST_F(GraphTest, UndefinedArgSubstitution) {
  expect_one_error("undefined_arg.yaml", 8, 31,
                   {"undefined argument 'rate' in '$(arg rate)'", "did you mean 'rate_hz'"});
}
// Issue 20 section 2: `a: $(arg a)` made the component silently disappear (no error at all).
TEST_F(GraphTest, ArgumentDefaultThatUsesItselfIsAnError) {
  expect_one_error("self_arg.yaml", 2, 9, {"argument 'rate' in '$(arg rate)' has no value here"});
}
TEST_F(GraphTest, ArgumentDefaultThatUsesALaterArgumentIsAnError) {
  expect_one_error("later_arg.yaml", 2, 11,
                   {"argument 'rate' in '$(arg rate)' has no value here", "declared above it"});
}
TEST_F(GraphTest, UnsetEnvironmentVariable) {
  ASSERT_EQ(std::getenv("AVS_GRAPH_TEST_NEVER_SET"), nullptr);
  expect_one_error("unset_env.yaml", 6, 29, {"environment variable 'AVS_GRAPH_TEST_NEVER_SET'"});
}
TEST_F(GraphTest, OverrideOfUndeclaredArg) {
  expect_one_error("overridable.yaml", 1, 1,
                   {"argument 'rate_h'", "command line", "did you mean 'rate_hz'"},
                   {{"rate_h", "5"}});
}
TEST_F(GraphTest, OverrideCheckedLikeAnyValue) {
  expect_one_error("overridable.yaml", 8, 31, {"parameter 'rate_hz'", "got 0"}, {{"rate_hz", "0"}});
}
TEST_F(GraphTest, RequiredArgNotGiven) {
  expect_one_error("required_arg.yaml", 2, 3,
                   {"argument 'rate_hz' has no default", "rate_hz:=VALUE"});
}
TEST_F(GraphTest, RequiredArgGiven) {
  const LoadResult result = load_graph(data("bad/required_arg.yaml"), {{"rate_hz", "20"}});
  ASSERT_TRUE(result.ok()) << all_errors(result);
  EXPECT_DOUBLE_EQ(component(*result.graph, "talker").parameters.get<double>("rate_hz"), 20.0);
}
TEST_F(GraphTest, ScalarWhereListExpected) {
  expect_one_error("scalar_for_list.yaml", 6, 29,
                   {"parameter 'gains'", "expected a list of numbers, got '3'"});
}
TEST_F(GraphTest, DuplicateComponentName) {
  expect_one_error("duplicate_component.yaml", 7, 37,
                   {"duplicate component name 'talker'", "duplicate_component.yaml:4:"});
}
TEST_F(GraphTest, DuplicateContainerName) {
  expect_one_error("duplicate_container.yaml", 5, 11, {"duplicate container name 'box'"});
}
TEST_F(GraphTest, BadExecutor) {
  expect_one_error("bad_executor.yaml", 3, 15,
                   {"'executor'", "'single_threaded', 'thread_per_component'", "'multi_threaded'"});
}
TEST_F(GraphTest, RealtimeSettingsAreCheckedWhereWritten) {
  expect_one_error("realtime_priority_without_fifo.yaml", 3, 37,
                   {"'priority'", "needs sched fifo or rr"});
  expect_one_error("realtime_fifo_without_priority.yaml", 3, 15,
                   {"container 'box' 'realtime'", "need a 'priority' (1-99)"});
  expect_one_error("realtime_cpu_twice.yaml", 3, 51, {"'cpus'", "CPU 1 listed twice"});
  const LoadResult bad = load_graph(data("bad/realtime_bad_values.yaml"), {});
  ASSERT_EQ(bad.errors.size(), 3u) << all_errors(bad);
  EXPECT_NE(bad.errors[0].str().find("'other', 'fifo', 'rr', got 'deadline'"), std::string::npos)
      << bad.errors[0].str();
  EXPECT_NE(bad.errors[1].str().find("'priority'"), std::string::npos) << bad.errors[1].str();
  EXPECT_NE(bad.errors[2].str().find("'lock_memory'"), std::string::npos) << bad.errors[2].str();
}
TEST_F(GraphTest, BadRespawnPolicy) {
  expect_one_error("bad_respawn.yaml", 3, 23,
                   {"'policy'", "'never', 'on_failure', 'always'", "'sometimes'"});
}
TEST_F(GraphTest, BadClockSource) {
  expect_one_error("bad_clock.yaml", 2, 11, {"clock 'source'", "'wall', 'sim'", "'simulated'"});
}
TEST_F(GraphTest, ClockMasterNamesUnknownContainer) {
  expect_one_error("unknown_master.yaml", 3, 11,
                   {"clock 'master'", "unknown container 'robott'", "did you mean 'robot'"});
}

TEST_F(GraphTest, CollectsAllErrorsNotJustTheFirst) {
  const std::string file = data("bad/three_errors.yaml");
  const LoadResult result = load_graph(file, {});
  ASSERT_EQ(result.errors.size(), 3u) << all_errors(result);
  EXPECT_EQ(result.errors[0].where.line, 6);
  EXPECT_NE(result.errors[0].message.find("rate_hz"), std::string::npos);
  EXPECT_EQ(result.errors[1].where.line, 6);
  EXPECT_NE(result.errors[1].message.find("mode"), std::string::npos);
  EXPECT_EQ(result.errors[2].where.line, 7);
  EXPECT_NE(result.errors[2].message.find("no_such_type"), std::string::npos);
}

TEST_F(GraphTest, MissingTopLevelFile) {
  const LoadResult result = load_graph(data("bad/no_such_file.yaml"), {});
  ASSERT_EQ(result.errors.size(), 1u) << all_errors(result);
  EXPECT_NE(result.errors[0].message.find("cannot open"), std::string::npos);
}

// ---- limits (issue 20 section 2) ----------------------------------------------------------

TEST_F(GraphTest, SecondYamlDocumentIsAnErrorNotIgnored) {
  expect_one_error("two_documents.yaml", 6, 1, {"second YAML document"});
}

// Found by tests/fuzz (fuzz_graph_loader): yaml-cpp's LoadAll never returned on these.
TEST_F(GraphTest, CommaWhereADocumentMayStartIsALocatedErrorNotAHang) {
  expect_one_error("comma_document.yaml", 1, 1, {"','"});
  expect_one_error("comma_after_document.yaml", 1, 18, {"','"});
}

/// A fresh folder for generated graphs, removed with the object.
struct TempDir {
  std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("avs_graph_limits_" + std::to_string(getpid()));
  TempDir() { std::filesystem::create_directories(path); }
  ~TempDir() { std::filesystem::remove_all(path); }
};

TEST_F(GraphTest, DeepIncludeChainIsALocatedErrorNotACrash) {
  // 4000 nested includes overflowed the loader's stack (SIGSEGV); the limit is 64.
  const TempDir dir;
  constexpr int kFiles = 300;
  for (int i = 0; i < kFiles; ++i) {
    std::ofstream out(dir.path / ("g" + std::to_string(i) + ".yaml"));
    if (i + 1 < kFiles) {
      out << "include:\n  - {file: g" << i + 1 << ".yaml}\n";
    } else {
      out << "containers:\n  - name: box\n    components:\n"
          << "      - {type: fake_talker, name: talker}\n";
    }
  }
  const LoadResult result = load_graph((dir.path / "g0.yaml").string(), {});
  ASSERT_EQ(result.errors.size(), 1u) << all_errors(result);
  EXPECT_NE(result.errors[0].message.find("nested deeper than 64"), std::string::npos)
      << result.errors[0].str();
  EXPECT_EQ(result.errors[0].where.line, 2);
}

TEST_F(GraphTest, IncludesThatDoubleAtEachLevelAreBoundedNotAFreeze) {
  // Each file includes the next twice: 40 levels (within the depth limit of 64) meant 2^40
  // file reads and a loader that never returned. The loader reads at most 1024 includes for a
  // graph and says so once, at the include that crossed the budget.
  const TempDir dir;
  constexpr int kFiles = 40;
  for (int i = 0; i < kFiles; ++i) {
    std::ofstream out(dir.path / ("d" + std::to_string(i) + ".yaml"));
    if (i + 1 < kFiles) {
      out << "include:\n  - {file: d" << i + 1 << ".yaml}\n  - {file: d" << i + 1 << ".yaml}\n";
    } else {
      out << "args:\n  unused: {default: 0}\n";
    }
  }
  const LoadResult result = load_graph((dir.path / "d0.yaml").string(), {});
  std::size_t budget_errors = 0;
  for (const Diagnostic& e : result.errors) {
    budget_errors += e.message.find("more than 1024 includes read") != std::string::npos ? 1 : 0;
  }
  EXPECT_EQ(budget_errors, 1u) << all_errors(result);
  EXPECT_FALSE(result.ok());
}

TEST_F(GraphTest, HugeValuesAreNotEchoedWhole) {
  const TempDir dir;
  const std::string type(100000, 'x');
  {
    std::ofstream out(dir.path / "huge.yaml");
    out << "containers:\n  - name: box\n    components:\n      - {type: " << type
        << ", name: talker}\n";
  }
  const LoadResult result = load_graph((dir.path / "huge.yaml").string(), {});
  ASSERT_EQ(result.errors.size(), 1u);
  EXPECT_LT(result.errors[0].message.size(), 2100u);
  EXPECT_NE(result.errors[0].message.find("more characters)"), std::string::npos);
}

// ---- good graphs ----------------------------------------------------------------------

const PortSpec& port_of(const std::string& type, const std::string& port) {
  return *runtime::ComponentRegistry::instance().find(type)->spec.find_port(port);
}

TEST_F(GraphTest, BasicGraphFillsDefaultsAndResolvesTopics) {
  const LoadResult result = load_graph(data("good/basic.yaml"), {});
  ASSERT_TRUE(result.ok()) << all_errors(result);
  const Graph& g = *result.graph;
  EXPECT_EQ(g.ns, "/avs");
  EXPECT_EQ(g.domain_id, 7);
  EXPECT_EQ(g.clock.source, ClockSpec::Source::wall);
  EXPECT_EQ(g.clock.master, "main");  // default: the first container
  ASSERT_EQ(g.containers.size(), 2u);
  EXPECT_EQ(g.containers[0].executor, ExecutorKind::thread_per_component);
  EXPECT_EQ(g.containers[0].respawn.kind, RespawnPolicy::Kind::on_failure);
  EXPECT_EQ(g.containers[0].respawn.max_restarts, 3);
  EXPECT_DOUBLE_EQ(g.containers[0].respawn.backoff_s, 0.5);
  EXPECT_EQ(g.containers[1].host, "visionpc");
  EXPECT_EQ(g.containers[1].executor, ExecutorKind::single_threaded);
  const RealtimeSpec& rt = g.containers[0].realtime;
  EXPECT_EQ(rt.policy, RealtimeSpec::Policy::fifo);
  EXPECT_EQ(rt.priority, 80);
  EXPECT_EQ(rt.cpus, (std::vector<int>{0, 1}));
  EXPECT_TRUE(rt.lock_memory);
  EXPECT_FALSE(g.containers[1].realtime.any()) << "not given: nothing real-time";
  EXPECT_EQ(g.containers[1].respawn.kind, RespawnPolicy::Kind::always);
  EXPECT_EQ(g.args.at("rate_hz"), "100");
  EXPECT_EQ(g.args.at("speed"), "1.0");

  const auto& talker = component(g, "talker");
  EXPECT_EQ(talker.type, "fake_talker");
  EXPECT_DOUBLE_EQ(talker.parameters.get<double>("rate_hz"), 100.0);  // integer given for a real
  EXPECT_EQ(talker.parameters.get<std::string>("label"), "hello world");
  EXPECT_EQ(talker.parameters.get<std::vector<double>>("gains"), (std::vector<double>{0.5, 2.0}));
  EXPECT_EQ(talker.parameters.get<int>("count"), 3);  // defaults filled in
  EXPECT_TRUE(talker.parameters.get<bool>("enabled"));
  EXPECT_EQ(talker.parameters.get<std::string>("mode"), "fast");
  EXPECT_EQ(talker.parameters.all().size(), 6u);
  EXPECT_EQ(talker.remaps.at("chatter"), "/chat");
  EXPECT_EQ(talker.qos.at("chatter"), *runtime::QosProfile::named("sensor_data"));
  EXPECT_EQ(talker.where.line, 15);

  const auto& listener = component(g, "listener");
  const auto& qos = listener.qos.at("chatter");
  EXPECT_EQ(qos.reliability, runtime::Reliability::best_effort);
  EXPECT_EQ(qos.depth, 3u);
  EXPECT_EQ(qos.durability, runtime::Durability::volatile_);
  ASSERT_TRUE(qos.deadline.has_value());
  EXPECT_EQ(*qos.deadline, std::chrono::milliseconds(250));

  EXPECT_EQ(port_topic(g, talker, port_of("fake_talker", "chatter")), "/chat");
  EXPECT_EQ(port_topic(g, listener, port_of("fake_listener", "chatter")), "/chat");
  EXPECT_EQ(port_topic(g, component(g, "camera"), port_of("fake_camera", "image")), "/avs/image");
  EXPECT_EQ(port_topic(g, component(g, "viewer"), port_of("fake_viewer", "image")), "/avs/image");
}

TEST_F(GraphTest, ArgOverrideReplacesDefault) {
  const LoadResult result = load_graph(data("good/basic.yaml"), {{"rate_hz", "50.5"}});
  ASSERT_TRUE(result.ok()) << all_errors(result);
  EXPECT_DOUBLE_EQ(component(*result.graph, "talker").parameters.get<double>("rate_hz"), 50.5);
  EXPECT_EQ(result.graph->args.at("rate_hz"), "50.5");
}

TEST_F(GraphTest, IncludesWithArgs) {
  const LoadResult result = load_graph(data("good/with_include.yaml"), {{"cam_rate", "42"}});
  ASSERT_TRUE(result.ok()) << all_errors(result);
  const Graph& g = *result.graph;
  ASSERT_EQ(g.containers.size(), 3u);
  EXPECT_EQ(g.containers[0].name, "left_box");  // includes come first: written first
  EXPECT_EQ(g.containers[1].name, "right_box");
  EXPECT_EQ(g.containers[2].name, "robot");
  EXPECT_EQ(g.files.size(), 3u);
  EXPECT_EQ(g.clock.source, ClockSpec::Source::sim);
  EXPECT_EQ(g.clock.mode, ClockSpec::Mode::realtime);
  EXPECT_DOUBLE_EQ(g.clock.real_time_factor, 0.5);
  EXPECT_EQ(g.clock.master, "robot");
  ASSERT_TRUE(g.clock.duration_s.has_value());
  EXPECT_DOUBLE_EQ(*g.clock.duration_s, 5.0);

  const auto& left = component(g, "left_camera");
  EXPECT_DOUBLE_EQ(left.parameters.get<double>("exposure_us"), 42.0);  // parent arg -> include arg
  EXPECT_EQ(left.remaps.at("image"), "/left/image");
  EXPECT_EQ(left.where.file, data("good/sub/camera.yaml"));
  const auto& right = component(g, "right_camera");
  EXPECT_DOUBLE_EQ(right.parameters.get<double>("exposure_us"), 100.0);  // included file's default
  EXPECT_EQ(port_topic(g, right, port_of("fake_camera", "image")), "/right/image");
  const auto& viewer_qos = component(g, "viewer").qos.at("image");
  EXPECT_EQ(viewer_qos.reliability, runtime::Reliability::best_effort);
  EXPECT_EQ(viewer_qos.depth, port_of("fake_viewer", "image").qos.depth);  // the rest kept
}

TEST_F(GraphTest, EnvironmentAndListArguments) {
  ASSERT_EQ(setenv("AVS_GRAPH_TEST_LABEL", "from env", 1), 0);
  ASSERT_EQ(unsetenv("AVS_GRAPH_TEST_UNSET"), 0);
  const LoadResult result = load_graph(data("good/substitutions.yaml"), {});
  ASSERT_TRUE(result.ok()) << all_errors(result);
  const auto& talker = component(*result.graph, "talker");
  EXPECT_EQ(talker.parameters.get<std::string>("label"), "from env");
  EXPECT_EQ(talker.parameters.get<std::string>("mode"), "slow");  // $(env NAME default)
  EXPECT_EQ(talker.parameters.get<std::vector<double>>("gains"),
            (std::vector<double>{1.0, 2.5, 3.0}));
  EXPECT_EQ(talker.parameters.get<int>("count"), 7);
  EXPECT_FALSE(talker.parameters.get<bool>("enabled"));
  EXPECT_DOUBLE_EQ(talker.parameters.get<double>("rate_hz"), 5.0);

  // A list argument overridden from the command line.
  const LoadResult overridden = load_graph(data("good/substitutions.yaml"), {{"gains", "[4, 5]"}});
  ASSERT_TRUE(overridden.ok()) << all_errors(overridden);
  EXPECT_EQ(component(*overridden.graph, "talker").parameters.get<std::vector<double>>("gains"),
            (std::vector<double>{4.0, 5.0}));
  unsetenv("AVS_GRAPH_TEST_LABEL");
}

TEST(ArgOverrides, SplitsNameValueWordsFromTheRest) {
  std::vector<std::string> rest;
  const auto args = parse_arg_overrides(
      {"g.yaml", "speed:=0.5", "--verbose", "name:=a:=b", ":=x", "speed:=0.7", "empty:="}, &rest);
  EXPECT_EQ(args.size(), 3u);
  EXPECT_EQ(args.at("speed"), "0.7");  // the later one wins
  EXPECT_EQ(args.at("name"), "a:=b");
  EXPECT_EQ(args.at("empty"), "");
  EXPECT_EQ(rest, (std::vector<std::string>{"g.yaml", "--verbose", ":=x"}));
  EXPECT_EQ(parse_arg_overrides({"a:=1"}, nullptr).at("a"), "1");
}

}  // namespace
}  // namespace avs::graph
