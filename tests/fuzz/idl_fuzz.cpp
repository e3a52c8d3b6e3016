// libFuzzer target: the IDL parser (TypeDatabase::add_idl, resolve) and the ROS 2 .msg text
// of every type it accepts. Errors are IdlError "fuzz.idl:line: what".
#include "avs/introspection/type_database.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace avs::introspection;
  try {
    TypeDatabase database;
    database.add_idl("fuzz.idl", avs::fuzz::text_of(data, size));
    database.resolve();
    for (const auto& [name, type] : database.types()) (void)ros2msg_definition(database, name);
  } catch (const IdlError& e) {
    avs::fuzz::expect_located(e, "fuzz.idl");
  }
  return 0;
}
