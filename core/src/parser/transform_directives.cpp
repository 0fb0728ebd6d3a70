// Directives that change the current transformation matrix (CTM). As in pbrt, every transform
// post-multiplies (CTM = CTM * T), so the transform written last applies to the object first.
#include "parser/scene_parser.h"

#include <fmt/core.h>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

namespace penumbra {

std::vector<double> SceneParser::read_numbers(const Token& d, size_t n) {
  // Brackets are optional: pbrt writes `Translate 1 2 3` but `Transform [ ... ]`.
  bool bracketed = tok_->peek().kind == TokenKind::LBracket;
  Token open = bracketed ? tok_->next() : Token{};
  std::vector<double> v;
  while (v.size() < n && tok_->peek().kind == TokenKind::Number)
    v.push_back(parse_number(tok_->next()));
  if (v.size() < n) {
    const Token& bad = tok_->peek();
    if (bad.kind != TokenKind::RBracket || !bracketed)
      throw Error(bad.loc, fmt::format("{} needs {} numbers; expected a number, got {}", d.text, n,
                                       describe(bad)));
    throw Error(open.loc, fmt::format("{} needs {} numbers, got {}", d.text, n, v.size()));
  }
  if (bracketed) {
    Token close = tok_->next();
    if (close.kind != TokenKind::RBracket)
      throw Error(close.loc, fmt::format("{} needs {} numbers; expected ']', got {}", d.text, n,
                                         describe(close)));
  }
  return v;
}

glm::dmat4 SceneParser::read_matrix(const Token& d) {
  // pbrt lists the matrix so that reading it column by column gives world-from-object.
  return glm::make_mat4(read_numbers(d, 16).data());
}

void SceneParser::identity(const Token&) { state_.ctm = glm::dmat4(1.0); }

void SceneParser::translate(const Token& d) {
  auto v = read_numbers(d, 3);
  state_.ctm = glm::translate(state_.ctm, glm::dvec3(v[0], v[1], v[2]));
}

void SceneParser::scale(const Token& d) {
  auto v = read_numbers(d, 3);
  state_.ctm = glm::scale(state_.ctm, glm::dvec3(v[0], v[1], v[2]));
}

void SceneParser::rotate(const Token& d) {
  auto v = read_numbers(d, 4);
  glm::dvec3 axis(v[1], v[2], v[3]);
  if (glm::length(axis) == 0.0) throw Error(d.loc, "Rotate needs a non-zero axis");
  state_.ctm = glm::rotate(state_.ctm, glm::radians(v[0]), glm::normalize(axis));
}

void SceneParser::look_at(const Token& d) {
  auto v = read_numbers(d, 9);
  glm::dvec3 eye(v[0], v[1], v[2]), look(v[3], v[4], v[5]), up(v[6], v[7], v[8]);
  if (glm::length(look - eye) == 0.0)
    throw Error(d.loc, "LookAt eye and look-at point are the same");
  if (glm::length(up) == 0.0) throw Error(d.loc, "LookAt up vector is zero");
  glm::dvec3 dir = glm::normalize(look - eye);
  glm::dvec3 side = glm::cross(glm::normalize(up), dir);
  if (glm::length(side) < 1e-9)
    throw Error(d.loc, "LookAt up vector is parallel to the viewing direction");
  glm::dvec3 right = glm::normalize(side);
  glm::dvec3 new_up = glm::cross(dir, right);
  glm::dmat4 world_from_camera(glm::dvec4(right, 0.0), glm::dvec4(new_up, 0.0),
                               glm::dvec4(dir, 0.0), glm::dvec4(eye, 1.0));
  state_.ctm = state_.ctm * glm::inverse(world_from_camera);
}

void SceneParser::transform(const Token& d) { state_.ctm = read_matrix(d); }

void SceneParser::concat_transform(const Token& d) { state_.ctm = state_.ctm * read_matrix(d); }

void SceneParser::coordinate_system(const Token& d) {
  named_coordinate_systems_[expect_string(d, "coordinate system name").text] = state_.ctm;
}

void SceneParser::coord_sys_transform(const Token& d) {
  Token name = expect_string(d, "coordinate system name");
  auto it = named_coordinate_systems_.find(name.text);
  if (it == named_coordinate_systems_.end()) {
    std::string known;
    for (const auto& [n, m] : named_coordinate_systems_) known += (known.empty() ? "" : ", ") + n;
    throw Error(name.loc, fmt::format("unknown coordinate system '{}' (defined: {})", name.text,
                                      known.empty() ? "none" : known));
  }
  state_.ctm = it->second;
}

}  // namespace penumbra
