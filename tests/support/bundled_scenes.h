// Copies of the bundled scenes with test-specific changes, written to a temporary folder.
#pragma once

#include <string>
#include <vector>

namespace penumbra::test {

/// The bundled Cornell box (scenes/cornell-box) in temp_dir(name) with its Integrator line replaced
/// by `integrator_line` (kept when empty) and, if `box_filter`, a box pixel filter instead of the
/// Gaussian (splats then land in one pixel, as pixel samples do). Returns the scene file's path.
/// Throws when the scene lacks the line a change needs (the copy would silently be the original).
std::string cornell_box_copy(const std::string& name, const std::string& integrator_line, bool box_filter = false);

/// Every whole scene under scenes/ (files with a WorldBegin directive at the start of a line; pieces
/// that other scenes Include, such as unit-cube.pbrt or scenes/bench/*-geometry.pbrt, are left out),
/// sorted.
std::vector<std::string> bundled_scene_files();

}  // namespace penumbra::test
