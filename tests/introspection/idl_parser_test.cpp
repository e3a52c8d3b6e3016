// The IDL parser: every file of the build parses, and unsupported input fails with file:line.
#include <gtest/gtest.h>

#include <random>
#include <string>

#include "avs/introspection/type_database.hpp"
#include "avs/msg/type_registry.hpp"

namespace avs::introspection {
namespace {

TEST(IdlParser, ParsesEveryStructOfTheBuild) {
  const auto& database = built_in_types();
  for (const auto& entry : avs::msg::all_types()) {
    EXPECT_NE(database.find(entry.dds_name), nullptr) << entry.dds_name;
  }
  EXPECT_EQ(database.types().size(), avs::msg::all_types().size());
}

TEST(IdlParser, ImageFieldsInOrder) {
  const auto& image = built_in_types().at("sensor_msgs::msg::dds_::Image_");
  ASSERT_EQ(image.fields.size(), 7u);
  EXPECT_EQ(image.file, "sensor_msgs.idl");
  EXPECT_EQ(image.fields[0].name, "header");
  EXPECT_EQ(image.fields[0].kind, FieldKind::kStruct);
  EXPECT_EQ(image.fields[0].struct_name, "std_msgs::msg::dds_::Header_");
  EXPECT_EQ(image.fields[3].name, "encoding");
  EXPECT_EQ(image.fields[3].kind, FieldKind::kString);
  EXPECT_EQ(image.fields[4].primitive, Primitive::kUint8);
  EXPECT_EQ(image.fields[6].name, "data");
  EXPECT_TRUE(image.fields[6].is_sequence);
  EXPECT_EQ(image.fields[6].primitive, Primitive::kUint8);
  EXPECT_FALSE(image.fields[6].array_length.has_value());
}

TEST(IdlParser, ConstantsAttachToTheirStruct) {
  const auto& point_field = built_in_types().at("sensor_msgs::msg::dds_::PointField_");
  ASSERT_EQ(point_field.constants.size(), 8u);
  EXPECT_EQ(point_field.constants[0].name, "INT8");
  EXPECT_EQ(point_field.constants[0].value, "1");
  EXPECT_EQ(point_field.constants[7].name, "FLOAT64");
  EXPECT_EQ(point_field.constants[7].value, "8");
  const auto& status = built_in_types().at("diagnostic_msgs::msg::dds_::DiagnosticStatus_");
  ASSERT_EQ(status.constants.size(), 4u);
  EXPECT_EQ(status.constants[3].primitive, Primitive::kOctet);
  EXPECT_EQ(built_in_types().at("avs_msgs::msg::dds_::MatchResult_").constants.size(), 4u);
  EXPECT_TRUE(built_in_types().at("sensor_msgs::msg::dds_::Image_").constants.empty());
}

TEST(IdlParser, RelativeNamesArraysBoundsAndDeclaratorLists) {
  TypeDatabase database;
  database.add_idl("t.idl", R"(
    module pkg { module msg { module dds_ {
      /* block
         comment */
      struct Inner_ { unsigned long long a; long b; short c, d; };
      @final struct Outer_ {
        Inner_ inner;
        ::pkg::msg::dds_::Inner_ absolute[2];
        double xyz[3];
        sequence<int32, 5> bounded;
        string<10> label;
      };
    }; }; };)");
  database.resolve();
  const auto& inner = database.at("pkg::msg::dds_::Inner_");
  ASSERT_EQ(inner.fields.size(), 4u);
  EXPECT_EQ(inner.fields[0].primitive, Primitive::kUint64);
  EXPECT_EQ(inner.fields[1].primitive, Primitive::kInt32);
  EXPECT_EQ(inner.fields[3].name, "d");
  const auto& outer = database.at("pkg::msg::dds_::Outer_");
  EXPECT_EQ(outer.fields[0].struct_name, "pkg::msg::dds_::Inner_");
  EXPECT_EQ(outer.fields[1].struct_name, "pkg::msg::dds_::Inner_");
  EXPECT_EQ(outer.fields[1].array_length, 2u);
  EXPECT_EQ(outer.fields[2].array_length, 3u);
  EXPECT_EQ(outer.fields[3].sequence_bound, 5u);
  EXPECT_EQ(outer.fields[4].string_bound, 10u);
  EXPECT_EQ(outer.line, 6);
}

// Parses `text` as bad.idl (and resolves) and returns the error message.
std::string error_of(const std::string& text) {
  try {
    TypeDatabase database;
    database.add_idl("bad.idl", text);
    database.resolve();
  } catch (const IdlError& error) {
    return error.what();
  }
  return "<no error>";
}

TEST(IdlParser, UnsupportedInputNamesFileAndLine) {
  EXPECT_EQ(error_of("module a {\n@appendable struct S { long x; };\n};"),
            "bad.idl:2: annotation @appendable is not supported (only @final: ROS 2 needs XCDR1)");
  EXPECT_EQ(error_of("module a {\n\n struct S { Missing_ x; };\n};"),
            "bad.idl:3: unknown type 'Missing_' in struct a::S");
  EXPECT_EQ(error_of("#if FOO\nmodule a {};\n#endif"),
            "bad.idl:1: preprocessor directive '#if FOO' is not supported (only include guards and "
            "#include)");
  EXPECT_EQ(error_of("module a {\n typedef long T;\n};"),
            "bad.idl:2: 'typedef' is not supported here (expected module, struct or const)");
  EXPECT_EQ(error_of("module a {\n const long X = 1;\n};"),
            "bad.idl:2: const is only supported inside a <Type>_Constants module");
  EXPECT_EQ(error_of("module a {\n module S_Constants { const long X = 1; };\n};"),
            "bad.idl:2: constants module for a::S_ but no such struct");
  EXPECT_EQ(error_of("module a { struct S {\n sequence<sequence<long>> x; }; };"),
            "bad.idl:2: sequences of sequences are not supported");
  EXPECT_EQ(error_of("module a { struct S {\n wstring x; }; };"),
            "bad.idl:2: type 'wstring' is not supported");
  EXPECT_EQ(error_of("module a { struct S { long x; }\n"),
            "bad.idl:2: expected ';', found '<end of file>'");
  EXPECT_EQ(error_of("module a { struct S { S x; }; };"), "bad.idl:1: struct a::S contains itself");
  EXPECT_EQ(error_of("module a { struct S { long x[0]; }; };"),
            "bad.idl:1: array length must be a positive 32-bit integer, found '0'");
}

// Seeded mutations of a real IDL file: each either parses or fails with an IdlError that
// names the file; never another exception (or a crash under the sanitiser build).
TEST(IdlParser, MutatedInputGivesIdlErrorsOnly) {
  std::string original;
  for (const auto& source : avs::msg::idl_sources()) {
    if (std::string(source.file_name) == "avs_msgs.idl") original = source.text;
  }
  ASSERT_FALSE(original.empty());
  const std::string alphabet = "{}<>;:,[]@#/*\"=- \nazAZ09_";
  std::mt19937 random(7);
  int errors = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    auto text = original;
    for (int i = 0, n = 1 + static_cast<int>(random() % 3); i < n; ++i) {
      text[random() % text.size()] = alphabet[random() % alphabet.size()];
    }
    if (random() % 4 == 0) text.resize(random() % text.size());
    try {
      TypeDatabase database;
      for (const auto& source : avs::msg::idl_sources()) {
        if (std::string(source.file_name) != "avs_msgs.idl")
          database.add_idl(source.file_name, source.text);
      }
      database.add_idl("avs_msgs.idl", text);
      database.resolve();
    } catch (const IdlError& error) {
      ++errors;
      EXPECT_EQ(std::string(error.what()).rfind("avs_msgs.idl:", 0), 0u) << error.what();
    }
  }
  EXPECT_GT(errors, 500);
}

}  // namespace
}  // namespace avs::introspection
