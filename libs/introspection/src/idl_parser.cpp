// Parser for the IDL subset our topic types use (docs/introspection.md): modules, structs,
// primitive/string/sequence/array members, scoped struct names and `<Type>_Constants` modules.
// Anything else is rejected with "file:line: ..." rather than guessed at.
#include <algorithm>
#include <cctype>
#include <functional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "avs/introspection/type_database.hpp"

namespace avs::introspection {

namespace {

enum class TokenKind { kIdentifier, kNumber, kString, kPunct, kEnd };

struct Token {
  TokenKind kind = TokenKind::kEnd;
  std::string text;
  int line = 0;
};

std::string join(const std::vector<std::string>& parts, std::size_t count) {
  std::string out;
  for (std::size_t i = 0; i < count; ++i) out += (i ? "::" : "") + parts[i];
  return out;
}

const std::map<std::string, Primitive, std::less<>>& primitive_keywords() {
  static const std::map<std::string, Primitive, std::less<>> keywords = {
      {"boolean", Primitive::kBool},   {"octet", Primitive::kOctet},
      {"char", Primitive::kChar},      {"int8", Primitive::kInt8},
      {"uint8", Primitive::kUint8},    {"int16", Primitive::kInt16},
      {"uint16", Primitive::kUint16},  {"int32", Primitive::kInt32},
      {"uint32", Primitive::kUint32},  {"int64", Primitive::kInt64},
      {"uint64", Primitive::kUint64},  {"float", Primitive::kFloat32},
      {"double", Primitive::kFloat64}, {"short", Primitive::kInt16},
  };
  return keywords;
}

}  // namespace

/// Recursive-descent parser over one file; fills a TypeDatabase (friend).
class IdlParser {
 public:
  IdlParser(TypeDatabase& database, std::string_view file_name, std::string_view text)
      : database_(database), file_(file_name), text_(text) {}

  void parse() {
    advance();
    std::vector<std::string> scope;
    parse_definitions(scope);
    if (token_.kind != TokenKind::kEnd) fail("unexpected '" + token_.text + "'");
  }

 private:
  [[noreturn]] void fail(const std::string& message, int line = 0) const {
    throw IdlError(file_ + ":" + std::to_string(line ? line : token_.line) + ": " + message);
  }

  // ---- lexer -------------------------------------------------------------------------
  void skip_space_and_comments() {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '\n') {
        ++line_;
        ++pos_;
        at_line_start_ = true;
      } else if (std::isspace(static_cast<unsigned char>(c))) {
        ++pos_;
      } else if (text_.substr(pos_, 2) == "//") {
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
      } else if (text_.substr(pos_, 2) == "/*") {
        const auto end = text_.find("*/", pos_ + 2);
        if (end == std::string_view::npos) fail("unterminated /* comment", line_);
        for (auto i = pos_; i < end; ++i) line_ += text_[i] == '\n';
        pos_ = end + 2;
      } else if (c == '#' && at_line_start_) {
        preprocessor_line();
      } else {
        return;
      }
    }
  }

  // Include guards and #include are accepted (all files of a set are parsed together);
  // anything that would need a real preprocessor is not.
  void preprocessor_line() {
    auto end = text_.find('\n', pos_);
    if (end == std::string_view::npos) end = text_.size();
    const std::string line(text_.substr(pos_, end - pos_));
    pos_ = end;
    std::vector<std::string> words;
    for (std::size_t i = 1; i < line.size();) {
      while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      const auto start = i;
      while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      if (i > start) words.push_back(line.substr(start, i - start));
    }
    const std::string directive = words.empty() ? "" : words[0];
    const bool guard = (directive == "ifndef" || directive == "define") && words.size() == 2;
    if (guard || directive == "endif" || directive == "include") return;
    fail(
        "preprocessor directive '" + line + "' is not supported (only include guards and #include)",
        line_);
  }

  void advance() {
    skip_space_and_comments();
    at_line_start_ = false;
    token_ = Token{TokenKind::kEnd, "<end of file>", line_};
    if (pos_ >= text_.size()) return;
    const char c = text_[pos_];
    const auto start = pos_;
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      while (pos_ < text_.size() &&
             (std::isalnum(static_cast<unsigned char>(text_[pos_])) || text_[pos_] == '_'))
        ++pos_;
      token_.kind = TokenKind::kIdentifier;
    } else if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') {
      while (pos_ < text_.size()) {
        const char d = text_[pos_];
        const bool exponent_sign =
            (d == '+' || d == '-') && (text_[pos_ - 1] == 'e' || text_[pos_ - 1] == 'E');
        if (!std::isalnum(static_cast<unsigned char>(d)) && d != '.' && !exponent_sign) break;
        ++pos_;
      }
      token_.kind = TokenKind::kNumber;
    } else if (c == '"') {
      ++pos_;
      while (pos_ < text_.size() && text_[pos_] != '"' && text_[pos_] != '\n')
        pos_ += text_[pos_] == '\\' ? 2 : 1;
      if (pos_ >= text_.size() || text_[pos_] != '"') fail("unterminated string literal", line_);
      ++pos_;
      token_.kind = TokenKind::kString;
    } else {
      pos_ += text_.substr(pos_, 2) == "::" ? 2 : 1;
      token_.kind = TokenKind::kPunct;
    }
    token_.text = std::string(text_.substr(start, pos_ - start));
  }

  bool accept(std::string_view text) {
    if (token_.kind == TokenKind::kString || token_.text != text) return false;
    advance();
    return true;
  }
  void expect(std::string_view text) {
    if (!accept(text)) fail("expected '" + std::string(text) + "', found '" + token_.text + "'");
  }
  std::string identifier(std::string_view what) {
    if (token_.kind != TokenKind::kIdentifier)
      fail("expected " + std::string(what) + ", found '" + token_.text + "'");
    auto name = token_.text;
    advance();
    return name;
  }
  std::uint32_t positive_integer(std::string_view what) {
    if (token_.kind != TokenKind::kNumber)
      fail("expected " + std::string(what) + ", found '" + token_.text + "'");
    std::size_t used = 0;
    unsigned long value = 0;
    try {
      value = std::stoul(token_.text, &used, 0);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != token_.text.size() || value == 0 || value > 0xffffffffUL) {
      fail(std::string(what) + " must be a positive 32-bit integer, found '" + token_.text + "'");
    }
    advance();
    return static_cast<std::uint32_t>(value);
  }

  // ---- grammar -----------------------------------------------------------------------
  void parse_definitions(std::vector<std::string>& scope) {
    while (token_.kind != TokenKind::kEnd && token_.text != "}") {
      if (accept(";")) continue;
      while (accept("@")) {
        const auto annotation = identifier("annotation name");
        if (annotation != "final") {
          fail("annotation @" + annotation + " is not supported (only @final: ROS 2 needs XCDR1)");
        }
      }
      if (accept("module")) {
        scope.push_back(identifier("module name"));
        expect("{");
        parse_definitions(scope);
        expect("}");
        expect(";");
        scope.pop_back();
      } else if (accept("struct")) {
        parse_struct(scope);
      } else if (token_.text == "const") {
        parse_constant(scope);
      } else {
        fail("'" + token_.text + "' is not supported here (expected module, struct or const)");
      }
    }
  }

  void parse_struct(const std::vector<std::string>& scope) {
    const int line = token_.line;
    StructType type;
    type.dds_name =
        join(scope, scope.size()) + (scope.empty() ? "" : "::") + identifier("struct name");
    type.file = file_;
    type.line = line;
    if (token_.text == ";") fail("forward declarations are not supported");
    if (token_.text == ":") fail("struct inheritance is not supported");
    expect("{");
    while (!accept("}")) {
      if (token_.text == "@") fail("member annotations are not supported");
      const int member_line = token_.line;
      const Field element = parse_type(/*allow_sequence=*/true);
      do {
        Field field = element;
        field.name = identifier("member name");
        if (accept("[")) {
          if (field.is_sequence) fail("arrays of sequences are not supported");
          field.array_length = positive_integer("array length");
          expect("]");
          if (token_.text == "[") fail("multi-dimensional arrays are not supported");
        }
        for (const auto& existing : type.fields) {
          if (existing.name == field.name) fail("duplicate member '" + field.name + "'");
        }
        if (field.kind == FieldKind::kStruct) {
          database_.pending_references_.push_back(
              {type.dds_name, type.fields.size(), scope, member_line});
        }
        type.fields.push_back(std::move(field));
      } while (accept(","));
      expect(";");
    }
    expect(";");
    if (type.fields.empty()) fail("struct " + type.dds_name + " has no members", line);
    if (database_.types_.count(type.dds_name))
      fail("struct " + type.dds_name + " defined twice", line);
    const auto name = type.dds_name;
    database_.types_.emplace(name, std::move(type));
  }

  Field parse_type(bool allow_sequence) {
    Field field;
    const auto keyword = token_.text;
    if (token_.kind != TokenKind::kIdentifier && token_.text != "::")
      fail("expected a type, found '" + keyword + "'");
    if (accept("sequence")) {
      if (!allow_sequence) fail("sequences of sequences are not supported");
      expect("<");
      field = parse_type(/*allow_sequence=*/false);
      field.is_sequence = true;
      if (accept(",")) field.sequence_bound = positive_integer("sequence bound");
      expect(">");
    } else if (accept("string")) {
      field.kind = FieldKind::kString;
      if (accept("<")) {
        field.string_bound = positive_integer("string bound");
        expect(">");
      }
    } else if (accept("unsigned")) {
      if (accept("short")) {
        field.primitive = Primitive::kUint16;
      } else {
        expect("long");
        field.primitive = accept("long") ? Primitive::kUint64 : Primitive::kUint32;
      }
    } else if (accept("long")) {
      if (token_.text == "double") fail("long double is not supported");
      field.primitive = accept("long") ? Primitive::kInt64 : Primitive::kInt32;
    } else if (const auto it = primitive_keywords().find(keyword);
               it != primitive_keywords().end()) {
      advance();
      field.primitive = it->second;
    } else if (keyword == "wstring" || keyword == "wchar" || keyword == "any" ||
               keyword == "fixed" || keyword == "map" || keyword == "union" || keyword == "enum") {
      fail("type '" + keyword + "' is not supported");
    } else {
      field.kind = FieldKind::kStruct;
      field.struct_name = accept("::") ? "::" : "";
      field.struct_name += identifier("type name");
      while (accept("::")) field.struct_name += "::" + identifier("type name");
    }
    return field;
  }

  void parse_constant(const std::vector<std::string>& scope) {
    const int line = token_.line;
    const std::string suffix = "_Constants";
    const auto& module = scope.empty() ? std::string() : scope.back();
    if (module.size() <= suffix.size() ||
        module.compare(module.size() - suffix.size(), suffix.size(), suffix) != 0) {
      fail("const is only supported inside a <Type>_Constants module");
    }
    advance();  // "const"
    const Field type = parse_type(/*allow_sequence=*/false);
    if (type.kind == FieldKind::kStruct)
      fail("constant of type '" + type.struct_name + "' is not supported");
    Constant constant{identifier("constant name"), type.kind, type.primitive, ""};
    expect("=");
    if (accept("-")) constant.value = "-";
    if (token_.kind == TokenKind::kIdentifier &&
        (token_.text == "TRUE" || token_.text == "FALSE")) {
      constant.value += token_.text == "TRUE" ? "true" : "false";
    } else if (token_.kind == TokenKind::kNumber || token_.kind == TokenKind::kString) {
      constant.value += token_.text;
    } else {
      fail("expected a literal value for constant " + constant.name + ", found '" + token_.text +
           "'");
    }
    if ((token_.kind == TokenKind::kString) != (constant.kind == FieldKind::kString)) {
      fail("literal " + token_.text + " does not match the type of constant " + constant.name);
    }
    advance();
    expect(";");
    const auto target =
        join(scope, scope.size() - 1) + "::" + module.substr(0, module.size() - suffix.size());
    auto& pending = database_.pending_constants_;
    if (pending.empty() || pending.back().target_dds_name != target ||
        pending.back().file != file_) {
      pending.push_back({target, file_, line, {}});
    }
    pending.back().constants.push_back(std::move(constant));
  }

  TypeDatabase& database_;
  std::string file_;
  std::string_view text_;
  std::size_t pos_ = 0;
  int line_ = 1;
  bool at_line_start_ = true;
  Token token_;
};

void TypeDatabase::add_idl(std::string_view file_name, std::string_view text) {
  IdlParser(*this, file_name, text).parse();
}

void TypeDatabase::resolve() {
  // 1. Struct references: absolute, or relative to the enclosing modules (innermost first).
  for (const auto& reference : pending_references_) {
    auto& owner = types_.at(reference.owner);
    auto& field = owner.fields[reference.field_index];
    const auto& written = field.struct_name;
    std::vector<std::string> candidates;
    if (written.rfind("::", 0) == 0) {
      candidates.push_back(written.substr(2));
    } else {
      for (auto depth = reference.scope.size() + 1; depth-- > 0;) {
        candidates.push_back(join(reference.scope, depth) + (depth ? "::" : "") + written);
      }
    }
    const auto found =
        std::find_if(candidates.begin(), candidates.end(),
                     [&](const std::string& name) { return types_.count(name) > 0; });
    if (found == candidates.end()) {
      throw IdlError(owner.file + ":" + std::to_string(reference.line) + ": unknown type '" +
                     written + "' in struct " + owner.dds_name);
    }
    field.struct_name = *found;
  }
  pending_references_.clear();
  // 2. Constants modules attach to "<Type>_" (DDS naming) or "<Type>".
  for (auto& pending : pending_constants_) {
    auto it = types_.find(pending.target_dds_name + "_");
    if (it == types_.end()) it = types_.find(pending.target_dds_name);
    if (it == types_.end()) {
      throw IdlError(pending.file + ":" + std::to_string(pending.line) + ": constants module for " +
                     pending.target_dds_name + "_ but no such struct");
    }
    for (auto& constant : pending.constants) it->second.constants.push_back(std::move(constant));
  }
  pending_constants_.clear();
  // 3. A struct may not contain itself (CDR has no pointers; ROS has no recursive messages).
  std::set<std::string> done;
  std::vector<std::string> path;
  const std::function<void(const StructType&)> visit = [&](const StructType& type) {
    if (done.count(type.dds_name)) return;
    if (std::find(path.begin(), path.end(), type.dds_name) != path.end()) {
      throw IdlError(type.file + ":" + std::to_string(type.line) + ": struct " + type.dds_name +
                     " contains itself");
    }
    path.push_back(type.dds_name);
    for (const auto& field : type.fields) {
      if (field.kind == FieldKind::kStruct) visit(types_.at(field.struct_name));
    }
    path.pop_back();
    done.insert(type.dds_name);
  };
  for (const auto& [name, type] : types_) visit(type);
}

const StructType* TypeDatabase::find(std::string_view dds_name) const {
  const auto it = types_.find(dds_name);
  return it == types_.end() ? nullptr : &it->second;
}

const StructType& TypeDatabase::at(std::string_view dds_name) const {
  if (const auto* type = find(dds_name)) return *type;
  throw std::out_of_range("unknown type '" + std::string(dds_name) + "' (not in this build's IDL)");
}

}  // namespace avs::introspection
