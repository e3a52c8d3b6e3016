// Component types the fuzzed graphs and deployments may name (the registry is empty in a fuzz
// target): every parameter kind and two topic types, so that validation runs past "unknown
// type" into parameters, remaps and QoS.
#pragma once

namespace avs::fuzz {

void register_fake_components();

}  // namespace avs::fuzz
