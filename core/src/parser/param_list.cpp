#include "parser/param_list.h"

#include <fmt/core.h>

#include <array>
#include <climits>
#include <cmath>
#include <sstream>
#include <string_view>

namespace penumbra {

namespace {

// What kind of value each accepted parameter type holds.
enum class ValueKind { Number, Integer, Bool, String, Spectrum };

struct TypeInfo {
  std::string_view name;
  ValueKind kind;
};

constexpr std::array<TypeInfo, 16> kTypes{{
    {"integer", ValueKind::Integer},
    {"float", ValueKind::Number},
    {"point2", ValueKind::Number},
    {"vector2", ValueKind::Number},
    {"point3", ValueKind::Number},
    {"vector3", ValueKind::Number},
    {"normal", ValueKind::Number},
    {"normal3", ValueKind::Number},
    {"point", ValueKind::Number},
    {"vector", ValueKind::Number},
    {"rgb", ValueKind::Number},
    {"bool", ValueKind::Bool},
    {"string", ValueKind::String},
    {"spectrum", ValueKind::Spectrum},
    {"blackbody", ValueKind::Number},
    {"texture", ValueKind::String},  // the name of a texture
}};

// pbrt-v4 types that Penumbra knowingly leaves out: none at the moment (kept for the error path).
constexpr std::array<std::string_view, 0> kUnsupportedTypes{};

std::string suggest_type(const std::string& given) {
  std::string best;
  size_t best_d = SIZE_MAX;
  for (const auto& t : kTypes) {
    size_t d = edit_distance(given, std::string(t.name));
    if (d < best_d) {
      best_d = d;
      best = t.name;
    }
  }
  return best_d <= 2 ? fmt::format("; did you mean '{}'?", best) : "";
}

ValueKind kind_of(const std::string& type, const FileLoc& loc) {
  for (const auto& t : kTypes)
    if (t.name == type) return t.kind;
  for (auto t : kUnsupportedTypes)
    if (t == type) throw Error(loc, fmt::format("parameter type '{}' is not supported", type));
  throw Error(loc, fmt::format("unknown parameter type '{}'{}", type, suggest_type(type)));
}

// Splits the declaration string "float fov" into type and name.
void split_declaration(const Token& decl, Param& p) {
  std::istringstream in(decl.text);
  std::string extra;
  if (!(in >> p.type >> p.name) || (in >> extra))
    throw Error(decl.loc, fmt::format("bad parameter declaration \"{}\": expected \"type name\", "
                                      "e.g. \"float radius\"",
                                      decl.text));
}

void add_number(Param& p, ValueKind kind, const Token& v) {
  if (v.kind != TokenKind::Number)
    throw Error(v.loc, fmt::format("parameter '{}' of type '{}' needs numbers, got {}", p.name,
                                   p.type, describe(v)));
  double x = parse_number(v);
  if (kind == ValueKind::Integer && (x != std::floor(x) || std::abs(x) > INT_MAX))
    throw Error(v.loc, fmt::format("parameter '{}' of type 'integer' needs an integer, got '{}'",
                                   p.name, v.text));
  p.numbers.push_back(x);
}

void add_bool(Param& p, const Token& v) {
  // pbrt accepts both bare and quoted true/false.
  bool word = v.kind == TokenKind::Word || v.kind == TokenKind::String;
  if (word && (v.text == "true" || v.text == "false")) {
    p.bools.push_back(v.text == "true");
    return;
  }
  throw Error(
      v.loc, fmt::format("bool parameter '{}' must be true or false, got {}", p.name, describe(v)));
}

void add_value(Param& p, ValueKind kind, const Token& v) {
  switch (kind) {
    case ValueKind::Bool: add_bool(p, v); return;
    case ValueKind::String:
      if (v.kind != TokenKind::String)
        throw Error(v.loc,
                    fmt::format("parameter '{}' of type '{}' needs quoted strings, got {}",
                                p.name, p.type, describe(v)));
      p.strings.push_back(v.text);
      return;
    case ValueKind::Spectrum:
      // A name ("metal-Cu-eta") or .spd file, or numbers; parser/spectrum_params.cpp makes RGB of them.
      if (v.kind == TokenKind::String) {
        p.strings.push_back(v.text);
        return;
      }
      add_number(p, kind, v);
      return;
    default: add_number(p, kind, v); return;
  }
}

bool is_value(const Token& t) {
  if (t.kind == TokenKind::Word) return t.text == "true" || t.text == "false";
  return t.kind == TokenKind::String || t.kind == TokenKind::Number;
}

void read_bracketed_values(Tokenizer& tok, Param& p, ValueKind kind) {
  Token open = tok.next();
  for (;;) {
    Token v = tok.next();
    if (v.kind == TokenKind::RBracket) break;
    if (v.kind == TokenKind::End)
      throw Error(open.loc, fmt::format("value list of parameter '{}' has no closing ']'", p.name));
    if (!is_value(v))
      throw Error(v.loc, fmt::format("unexpected {} in the values of parameter '{}' (missing ']'?)",
                                     describe(v), p.name));
    add_value(p, kind, v);
  }
  if (p.count() == 0) throw Error(open.loc, fmt::format("parameter '{}' has no values", p.name));
}

}  // namespace

Param parse_param(Tokenizer& tok) {
  Token decl = tok.next();
  if (decl.kind != TokenKind::String)
    throw Error(decl.loc,
                fmt::format("expected a parameter \"type name\", got {}", describe(decl)));
  Param p;
  p.loc = decl.loc;
  split_declaration(decl, p);
  ValueKind kind = kind_of(p.type, p.loc);
  const Token& next = tok.peek();
  if (next.kind == TokenKind::LBracket) {
    read_bracketed_values(tok, p, kind);
  } else if (is_value(next)) {
    add_value(p, kind, tok.next());
  } else {
    throw Error(p.loc, fmt::format("parameter '{}' has no value", p.name));
  }
  return p;
}

ParamSet parse_param_list(Tokenizer& tok) {
  ParamSet params;
  while (tok.peek().kind == TokenKind::String) params.add(parse_param(tok));
  return params;
}

}  // namespace penumbra
