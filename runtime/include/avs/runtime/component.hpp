// The component contract (in the spirit of rclcpp_components): a component is a class
// with a constructor taking a ComponentContext and a static spec() describing its
// parameters and topics; AVS_REGISTER_COMPONENT puts it in the registry by type name.
// The container chooses threads; the component only sees callbacks.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "avs/msg/type_registry.hpp"
#include "avs/msg/type_support.hpp"
#include "avs/runtime/logger.hpp"
#include "avs/runtime/parameters.hpp"
#include "avs/runtime/qos.hpp"
#include "avs/runtime/sample.hpp"
#include "avs/runtime/time.hpp"

namespace avs::runtime {

/// A topic a component publishes or subscribes to. `name` is the port (what remaps refer
/// to); `default_topic` the ROS topic name used when not remapped (relative names get
/// the graph's namespace).
struct PortSpec {
  std::string name;
  std::string dds_type;
  std::string default_topic;
  QosProfile qos;
};

template <class T>
PortSpec port(std::string name, std::string default_topic, QosProfile qos = {}) {
  return {std::move(name), msg::TypeSupport<T>::dds_name, std::move(default_topic), qos};
}

struct ComponentSpec {
  std::string type;
  std::string description;
  std::vector<ParamSpec> parameters;
  std::vector<PortSpec> publishes;
  std::vector<PortSpec> subscribes;
  /// For components whose parameters are bound to a core Config (config_params.hpp): the
  /// parameters whose spec default does not reproduce the Config's default (tests walk the
  /// registry with it). Empty function: the component has no bound core Config.
  std::function<std::vector<std::string>()> default_mismatches = {};
  /// Topics chosen at run time (bag_player, bag_recorder): the component publishes and
  /// subscribes serialised samples of any topic with a type this build knows, named by its
  /// ROS topic (ComponentContext::serialized_publisher / serialized_subscription) instead of
  /// ports declared above.
  bool open_ports = false;

  const ParamSpec* find_parameter(std::string_view name) const;
  const PortSpec* find_port(std::string_view name) const;
};

/// Type-erased publishing end, implemented by the container.
class PublisherCore {
 public:
  virtual ~PublisherCore() = default;
  virtual void publish(std::shared_ptr<const void> sample) = 0;
  /// Publisher::publish_unchanged.
  virtual void publish_unchanged(std::shared_ptr<const void> sample) { publish(std::move(sample)); }
  virtual const std::string& topic() const = 0;
  /// Readers now: subscriptions of this container's components plus matched readers of
  /// other participants (a source that must not start before its receiver is there).
  virtual std::size_t reader_count() const = 0;
};

/// Publishes samples of T: components in the same container get the same shared sample
/// (no copy); other processes get it over DDS.
template <class T>
class Publisher {
 public:
  Publisher() = default;
  explicit Publisher(std::shared_ptr<PublisherCore> core)
      : core_(std::move(core)), pool_(std::make_shared<SamplePool<T>>()) {}
  void publish(std::shared_ptr<const T> sample) const { core_->publish(std::move(sample)); }
  /// The same for a sample equal to the last one published but for its header's stamp (a
  /// camera model sent with every image): on a latched (transient local) topic with no reader
  /// in another process it is not serialised into the DDS history for nobody, which keeps the
  /// earlier, equal copy for a late joiner; everyone matched gets it as with publish().
  void publish_unchanged(std::shared_ptr<const T> sample) const {
    core_->publish_unchanged(std::move(sample));
  }
  /// A sample to fill and publish, reused from an earlier message of this publisher once its
  /// subscribers have let it go (SamplePool: no allocation per message once warm, as ROS 2's
  /// loaned messages). It holds that message's values: set every field.
  std::shared_ptr<T> loan() const {
    if (!pool_) throw std::logic_error("Publisher::loan on a publisher the container did not make");
    return pool_->acquire();
  }
  const std::string& topic() const { return core_->topic(); }
  std::size_t reader_count() const { return core_->reader_count(); }
  explicit operator bool() const { return core_ != nullptr; }

 private:
  std::shared_ptr<PublisherCore> core_;
  /// Shared by copies of the publisher; not thread-safe: loan from one thread (the component's
  /// callbacks), as every component here does.
  std::shared_ptr<SamplePool<T>> pool_;
};

/// Publishing end for serialised samples (CDR, the 4-byte encapsulation header included) of
/// a type known only at run time: the container deserialises each once for its own
/// subscribers (who get it as if published typed) and writes it to DDS.
class SerializedPublisher {
 public:
  virtual ~SerializedPublisher() = default;
  /// Throws Error naming the topic and type when the bytes are not a sample of it.
  virtual void publish(std::span<const std::byte> cdr) = 0;
  virtual const std::string& topic() const = 0;
};

using TimerId = std::uint64_t;

/// What a component gets from its container. Publishers and subscriptions are made for
/// ports declared in the spec; timers run while the component is active.
class ComponentContext {
 public:
  virtual ~ComponentContext() = default;

  virtual const std::string& name() const = 0;
  virtual const ParameterValues& parameters() const = 0;
  virtual const Logger& log() const = 0;
  /// Wall time, or simulated time when the graph runs in sim time.
  virtual Time now() const = 0;
  virtual bool uses_sim_time() const = 0;
  /// The DDS domain and partition of the container's graph: for a component that needs a
  /// participant of its own (the live view's discovery, components/view).
  virtual int dds_domain() const = 0;
  virtual const std::string& dds_partition() const = 0;

  /// Calls `callback` every `period` of the context's clock, on the component's thread.
  virtual TimerId create_timer(Duration period, std::function<void()> callback) = 0;
  virtual void cancel_timer(TimerId id) = 0;

  /// For components with ComponentSpec::open_ports: a publisher of `ros_topic` (relative
  /// names get the graph's namespace; the instance's remaps apply, keyed by the topic name)
  /// with DDS type `dds_type` ("sensor_msgs::msg::dds_::Image_"). Throws Error for an unknown
  /// type, a component without open ports, or once the container runs.
  virtual std::shared_ptr<SerializedPublisher> serialized_publisher(const std::string& ros_topic,
                                                                    const std::string& dds_type,
                                                                    const QosProfile& qos) = 0;
  /// For components with ComponentSpec::open_ports: `callback` gets every sample of
  /// `ros_topic`, serialised, from this container's publishers and from other processes.
  /// An empty `dds_type` means the type the graph's publishers of the topic declare.
  /// Returns the DDS type subscribed to.
  virtual std::string serialized_subscription(
      const std::string& ros_topic, const std::string& dds_type, const QosProfile& qos,
      std::function<void(std::span<const std::byte> cdr)> callback) = 0;

  /// Ends the container's run, as Ctrl-C would (components are deactivated and shut down;
  /// the exit status is 0): for a component that knows the run is complete, e.g. a bag
  /// player at the end of its file. `why` is logged.
  virtual void request_stop(const std::string& why) = 0;

  template <class T>
  T param(const std::string& name) const {
    return parameters().template get<T>(name);
  }

  template <class T>
  Publisher<T> publisher(std::string_view port) {
    return Publisher<T>(make_publisher(port, type_entry<T>()));
  }

  /// `callback` runs on the component's thread with samples from this container
  /// (shared, not copied) and from other processes.
  template <class T>
  void subscribe(std::string_view port, std::function<void(SamplePtr<T>)> callback) {
    make_subscription(port, type_entry<T>(),
                      [cb = std::move(callback)](std::shared_ptr<const void> sample) {
                        cb(std::static_pointer_cast<const T>(std::move(sample)));
                      });
  }

 protected:
  virtual std::shared_ptr<PublisherCore> make_publisher(std::string_view port,
                                                        const msg::TypeEntry& type) = 0;
  virtual void make_subscription(std::string_view port, const msg::TypeEntry& type,
                                 std::function<void(std::shared_ptr<const void>)> callback) = 0;

 private:
  template <class T>
  static const msg::TypeEntry& type_entry() {
    static const msg::TypeEntry entry{msg::TypeSupport<T>::dds_name,
                                      msg::TypeSupport<T>::descriptor(), sizeof(T)};
    return entry;
  }
};

/// Base class of all components. Lifecycle: constructed (= configured, parameters read,
/// publishers and subscriptions made) -> on_activate -> on_deactivate -> on_shutdown ->
/// destroyed. Throwing from any step fails that component with the error reported.
class Component {
 public:
  explicit Component(ComponentContext& context) : context_(context) {}
  Component(const Component&) = delete;
  Component& operator=(const Component&) = delete;
  virtual ~Component() = default;

  virtual void on_activate() {}
  virtual void on_deactivate() {}
  virtual void on_shutdown() {}

  /// Extra key/values for this component's status on /diagnostics (after the container's
  /// callbacks / callback_ms_* values), e.g. dropped inputs. Called by the container's
  /// diagnostics timer, possibly on another thread than the component's callbacks: guard
  /// the state it reads.
  virtual std::vector<std::pair<std::string, std::string>> diagnostic_values() const { return {}; }

  /// Dynamic parameters (ParamSpec::dynamic) changed while the graph runs (`avs param set`,
  /// ROS 2 set_parameters). Called on the component's thread between two of its callbacks,
  /// never during one: `values` holds every parameter with the new ones, `changed` names
  /// those that changed. Apply them (e.g. re-make the core's Config), or throw to refuse the
  /// whole change (the message goes back to the caller, nothing is applied). The container
  /// has checked names, types, ranges and the dynamic flag; context().parameters() shows the
  /// new values once this returns. The default refuses loudly: a component that declares a
  /// dynamic parameter must override it.
  virtual void on_parameters_changed(const ParameterValues& values,
                                     const std::vector<std::string>& changed);

 protected:
  ComponentContext& context() { return context_; }
  const Logger& log() const { return context_.log(); }

 private:
  ComponentContext& context_;
};

using ComponentFactory = std::function<std::unique_ptr<Component>(ComponentContext&)>;

struct RegisteredComponent {
  ComponentSpec spec;
  ComponentFactory factory;
};

/// All component types linked into this program, by type name.
class ComponentRegistry {
 public:
  static ComponentRegistry& instance();
  void add(ComponentSpec spec, ComponentFactory factory);
  const RegisteredComponent* find(std::string_view type) const;
  std::vector<const RegisteredComponent*> all() const;

 private:
  std::vector<std::unique_ptr<RegisteredComponent>> entries_;
};

template <class C>
bool register_component() {
  ComponentRegistry::instance().add(C::spec(),
                                    [](ComponentContext& ctx) { return std::make_unique<C>(ctx); });
  return true;
}

}  // namespace avs::runtime

/// Registers component class C (which has `static ComponentSpec spec()`). Use once, in C's .cpp.
#define AVS_REGISTER_COMPONENT(C) \
  [[maybe_unused]] static const bool avs_registered_##C = ::avs::runtime::register_component<C>()
