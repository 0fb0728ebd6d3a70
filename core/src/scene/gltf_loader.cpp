#include "scene/gltf_loader.h"

#include "util/input_file.h"

#include <fmt/core.h>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <tiny_gltf.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>

namespace penumbra {

namespace {

// Buffers and images a glTF file names are read as every other input is: only regular files, up to
// their size (util/input_file.h).
bool read_regular_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void*) {
  try {
    std::string bytes = read_input_file(path, "glTF buffer");
    out->assign(bytes.begin(), bytes.end());
    return true;
  } catch (const Error& e) {
    if (err) *err += std::string(e.what()) + "\n";
    return false;
  }
}

// Textures are not supported yet: accept image entries without decoding them.
bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
  return true;
}

class Reader {
 public:
  Reader(const tinygltf::Model& model, const std::string& path, const FileLoc& loc)
      : model_(model), path_(path), loc_(loc) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw Error(loc_, fmt::format("glTF file '{}': {}", path_, what));
  }

  // Reads `components` numbers per element of an accessor as doubles, honouring byte strides,
  // normalised integer encodings and buffer bounds.
  std::vector<double> read(int accessor_index, int components, const char* what) const {
    if (accessor_index < 0 || accessor_index >= static_cast<int>(model_.accessors.size()))
      fail(fmt::format("{} refers to accessor {}, which does not exist", what, accessor_index));
    const tinygltf::Accessor& a = model_.accessors[accessor_index];
    if (a.sparse.isSparse) fail(fmt::format("{} uses a sparse accessor, which is not supported", what));
    int n = tinygltf::GetNumComponentsInType(a.type);
    if (n != components) fail(fmt::format("{} has {} components per element, expected {}", what, n, components));
    if (a.bufferView < 0 || a.bufferView >= static_cast<int>(model_.bufferViews.size()))
      fail(fmt::format("{} has no valid buffer view", what));
    const tinygltf::BufferView& view = model_.bufferViews[a.bufferView];
    if (view.buffer < 0 || view.buffer >= static_cast<int>(model_.buffers.size()))
      fail(fmt::format("{} refers to a missing buffer", what));
    const std::vector<unsigned char>& data = model_.buffers[view.buffer].data;
    int size = tinygltf::GetComponentSizeInBytes(a.componentType);
    if (size <= 0) fail(fmt::format("{} has an unknown component type {}", what, a.componentType));
    int stride = a.ByteStride(view);
    if (stride <= 0) fail(fmt::format("{} has an invalid byte stride", what));
    // Every offset and the count come from the file: compared by division, so that no product or
    // sum can wrap around.
    size_t view_end = view.byteLength > SIZE_MAX - view.byteOffset ? SIZE_MAX : view.byteOffset + view.byteLength;
    size_t available = std::min(data.size(), view_end);
    size_t element = static_cast<size_t>(n) * size;
    bool fits = view.byteOffset <= available && a.byteOffset <= available - view.byteOffset;
    size_t begin = fits ? view.byteOffset + a.byteOffset : available;
    if (fits && a.count > 0)
      fits = element <= available - begin && a.count - 1 <= (available - begin - element) / static_cast<size_t>(stride);
    if (!fits)
      fail(fmt::format("{} reads past the end of its buffer ({} elements of {} bytes from byte {}, {} bytes available)",
                       what, a.count, element, view.byteOffset + a.byteOffset, available));
    std::vector<double> out;
    out.reserve(a.count * n);
    for (size_t i = 0; i < a.count; ++i)
      for (int c = 0; c < n; ++c) out.push_back(component(&data[begin + i * stride + c * size], a.componentType, a.normalized));
    return out;
  }

 private:
  static double component(const unsigned char* p, int type, bool normalized) {
    auto get = [&](auto v) {
      std::memcpy(&v, p, sizeof v);
      return v;
    };
    switch (type) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT: return get(float{});
      case TINYGLTF_COMPONENT_TYPE_DOUBLE: return get(double{});
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? get(uint8_t{}) / 255.0 : get(uint8_t{});
      case TINYGLTF_COMPONENT_TYPE_BYTE: return normalized ? std::max(get(int8_t{}) / 127.0, -1.0) : get(int8_t{});
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return normalized ? get(uint16_t{}) / 65535.0 : get(uint16_t{});
      case TINYGLTF_COMPONENT_TYPE_SHORT: return normalized ? std::max(get(int16_t{}) / 32767.0, -1.0) : get(int16_t{});
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return get(uint32_t{});
      case TINYGLTF_COMPONENT_TYPE_INT: return get(int32_t{});
    }
    return 0.0;
  }

  const tinygltf::Model& model_;
  const std::string& path_;
  const FileLoc& loc_;
};

glm::dmat4 node_transform(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());
  glm::dmat4 m(1.0);
  if (node.translation.size() == 3) m[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
  if (node.rotation.size() == 4) {
    glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);  // glTF stores x y z w
    m = m * glm::mat4_cast(q);
  }
  if (node.scale.size() == 3) m = m * glm::scale(glm::dmat4(1.0), glm::dvec3(node.scale[0], node.scale[1], node.scale[2]));
  return m;
}

}  // namespace

std::vector<GltfPrimitive> load_gltf(const std::string& path, const FileLoc& loc) {
  if (!std::filesystem::exists(path)) throw Error(loc, fmt::format("glTF file '{}' does not exist", path));
  std::string bytes = read_input_file(path, "glTF file", loc);
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(skip_image, nullptr);
  loader.SetFsCallbacks(tinygltf::FsCallbacks{&tinygltf::FileExists, &tinygltf::ExpandFilePath, &read_regular_file,
                                              &tinygltf::WriteWholeFile, nullptr});
  tinygltf::Model model;
  std::string err, warn;
  bool binary = std::filesystem::path(path).extension() == ".glb";
  std::string base_dir = std::filesystem::path(path).parent_path().string();
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  bool ok = false;
  try {  // tinygltf reports through `err`, but a buffer length it believes can still fail to allocate
    ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, data, static_cast<unsigned>(bytes.size()), base_dir)
                : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(), static_cast<unsigned>(bytes.size()), base_dir);
  } catch (const std::exception& e) {
    err = e.what();
  }
  if (!ok) throw Error(loc, fmt::format("glTF file '{}' cannot be read: {}", path, err.empty() ? warn : err));
  Reader reader(model, path, loc);
  if (!model.textures.empty())
    warning(loc, fmt::format("glTF file '{}': textures are ignored; material factors are used", path));

  std::vector<GltfPrimitive> out;
  // Walks the node tree, accumulating transforms; a node visited twice is an instance of its mesh,
  // copied. A few nodes that name each other several times can expand to astronomically many
  // instances: the walk stops with an error past kMaxNodeVisits.
  constexpr size_t kMaxNodeVisits = 1'000'000;
  size_t visits = 0;
  std::function<void(int, const glm::dmat4&, int)> visit = [&](int node_index, const glm::dmat4& parent, int depth) {
    if (node_index < 0 || node_index >= static_cast<int>(model.nodes.size()) || depth > 64)
      reader.fail(fmt::format("node {} does not exist or the node tree is cyclic", node_index));
    if (++visits > kMaxNodeVisits)
      reader.fail(fmt::format("the node tree expands to more than {} node instances", kMaxNodeVisits));
    const tinygltf::Node& node = model.nodes[node_index];
    glm::dmat4 m = parent * node_transform(node);
    if (node.mesh >= 0) {
      if (node.mesh >= static_cast<int>(model.meshes.size())) reader.fail(fmt::format("node {} refers to missing mesh {}", node_index, node.mesh));
      glm::dmat3 normal_matrix = glm::transpose(glm::inverse(glm::dmat3(m)));
      const tinygltf::Mesh& mesh = model.meshes[node.mesh];
      for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
        const tinygltf::Primitive& prim = mesh.primitives[pi];
        std::string what = fmt::format("mesh '{}' primitive {}", mesh.name, pi);
        if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1)
          reader.fail(fmt::format("{} has mode {}; only triangles (4) are supported", what, prim.mode));
        auto pos = prim.attributes.find("POSITION");
        if (pos == prim.attributes.end()) reader.fail(what + " has no POSITION attribute");
        GltfPrimitive g;
        std::vector<double> p = reader.read(pos->second, 3, (what + " POSITION").c_str());
        for (size_t i = 0; i < p.size(); i += 3) g.P.push_back(Vec3(m * glm::dvec4(p[i], p[i + 1], p[i + 2], 1.0)));
        auto same_count = [&](const std::vector<double>& values, size_t per_vertex, const char* attribute) {
          if (values.size() / per_vertex != g.P.size())
            reader.fail(fmt::format("{} has {} {} values but {} positions", what, values.size() / per_vertex, attribute,
                                    g.P.size()));
        };
        if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
          std::vector<double> n = reader.read(it->second, 3, (what + " NORMAL").c_str());
          same_count(n, 3, "NORMAL");
          for (size_t i = 0; i < n.size(); i += 3) g.N.push_back(Vec3(glm::normalize(normal_matrix * glm::dvec3(n[i], n[i + 1], n[i + 2]))));
        }
        if (auto it = prim.attributes.find("TEXCOORD_0"); it != prim.attributes.end()) {
          std::vector<double> t = reader.read(it->second, 2, (what + " TEXCOORD_0").c_str());
          same_count(t, 2, "TEXCOORD_0");
          for (size_t i = 0; i < t.size(); i += 2) g.uv.push_back(Vec2(t[i], t[i + 1]));
        }
        if (prim.indices >= 0) {
          for (double v : reader.read(prim.indices, 1, (what + " indices").c_str())) {
            // Indices are unsigned in glTF: checked against the vertex count before any conversion.
            if (!(v >= 0.0 && v < static_cast<double>(g.P.size())))
              reader.fail(fmt::format("{} has index {:.0f}, but only {} vertices", what, v, g.P.size()));
            g.indices.push_back(static_cast<int>(v));
          }
        } else {
          for (size_t i = 0; i < g.P.size(); ++i) g.indices.push_back(static_cast<int>(i));
        }
        // Triangles take three vertices each; a remainder would be read as part of a triangle that
        // does not exist (found by the fuzzer).
        if (g.indices.size() % 3 != 0)
          reader.fail(fmt::format("{} has {} {}, not a multiple of 3 for triangles", what, g.indices.size(),
                                  prim.indices >= 0 ? "indices" : "vertices (and no indices)"));
        if (prim.material >= 0) {
          if (prim.material >= static_cast<int>(model.materials.size())) reader.fail(what + " refers to a missing material");
          const tinygltf::Material& mat = model.materials[prim.material];
          const auto& pbr = mat.pbrMetallicRoughness;
          GltfMaterial gm;
          if (pbr.baseColorFactor.size() >= 3) gm.base_color = Rgb(pbr.baseColorFactor[0], pbr.baseColorFactor[1], pbr.baseColorFactor[2]);
          gm.metallic = static_cast<float>(pbr.metallicFactor);
          gm.roughness = static_cast<float>(pbr.roughnessFactor);
          gm.name = mat.name;
          g.material = gm;
        }
        out.push_back(std::move(g));
      }
    }
    for (int child : node.children) visit(child, m, depth + 1);
  };
  int scene = model.defaultScene >= 0 ? model.defaultScene : 0;
  if (model.scenes.empty()) {
    for (size_t i = 0; i < model.nodes.size(); ++i) visit(static_cast<int>(i), glm::dmat4(1.0), 0);
  } else {
    if (scene >= static_cast<int>(model.scenes.size())) reader.fail("the default scene does not exist");
    for (int n : model.scenes[scene].nodes) visit(n, glm::dmat4(1.0), 0);
  }
  if (out.empty()) reader.fail("contains no triangle meshes");
  return out;
}

}  // namespace penumbra
