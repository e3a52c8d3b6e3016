// libFuzzer target: the CDR reader (decode_cdr, then to_yaml) on samples of our built-in
// types, as any DDS writer on the domain may send them. Input: the DDS type name, a NUL, then
// the serialised sample (encapsulation header first); an unknown name is skipped. Errors are
// CdrError.
#include <algorithm>
#include <span>
#include <string_view>

#include "avs/introspection/cdr_reader.hpp"
#include "avs/introspection/type_database.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace avs::introspection;
  const std::uint8_t* nul = std::find(data, data + size, std::uint8_t{0});
  if (nul == data + size) return 0;
  const std::string_view type(reinterpret_cast<const char*>(data),
                              static_cast<std::size_t>(nul - data));
  const TypeDatabase& database = built_in_types();
  if (database.find(type) == nullptr) return 0;
  try {
    const Value value = decode_cdr(database, type, std::span(nul + 1, data + size));
    (void)to_yaml(value);
  } catch (const CdrError&) {
    // The reader's documented refusal of malformed input.
  }
  return 0;
}
