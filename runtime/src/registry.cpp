#include "avs/runtime/component.hpp"

namespace avs::runtime {

const ParamSpec* ComponentSpec::find_parameter(std::string_view name) const {
  for (const auto& p : parameters) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

const PortSpec* ComponentSpec::find_port(std::string_view name) const {
  for (const auto& p : publishes) {
    if (p.name == name) return &p;
  }
  for (const auto& p : subscribes) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

void Component::on_parameters_changed(const ParameterValues& /*values*/,
                                      const std::vector<std::string>& changed) {
  std::string names;
  for (const auto& n : changed) names += (names.empty() ? "" : ", ") + n;
  throw Error("not implemented: component '" + context_.name() +
              "' declares dynamic parameters but does not apply changes (" + names + ")");
}

ComponentRegistry& ComponentRegistry::instance() {
  static ComponentRegistry registry;
  return registry;
}

void ComponentRegistry::add(ComponentSpec spec, ComponentFactory factory) {
  if (find(spec.type) != nullptr) throw Error("component type '" + spec.type + "' registered twice");
  entries_.push_back(std::make_unique<RegisteredComponent>(
      RegisteredComponent{std::move(spec), std::move(factory)}));
}

const RegisteredComponent* ComponentRegistry::find(std::string_view type) const {
  for (const auto& e : entries_) {
    if (e->spec.type == type) return e.get();
  }
  return nullptr;
}

std::vector<const RegisteredComponent*> ComponentRegistry::all() const {
  std::vector<const RegisteredComponent*> out;
  for (const auto& e : entries_) out.push_back(e.get());
  return out;
}

}  // namespace avs::runtime
