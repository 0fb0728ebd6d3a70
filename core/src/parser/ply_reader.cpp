// A small PLY reader written for Penumbra. Debian 12 packages no PLY library (rply, tinyply,
// happly) and Assimp would be a heavy dependency for one format; the subset pbrt scenes need
// (vertices with positions, normals and uvs; polygon faces) fits in this file.
#include "parser/ply_reader.h"

#include "util/input_file.h"

#include <fmt/core.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <sstream>

namespace penumbra {

namespace {

enum class Scalar { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };
enum class Format { Ascii, BinaryLittleEndian, BinaryBigEndian };

struct Property {
  std::string name;
  Scalar type = Scalar::Float32;  // of the values (list items for a list)
  bool is_list = false;
  Scalar count_type = Scalar::UInt8;
};

struct Element {
  std::string name;
  size_t count = 0;
  std::vector<Property> props;
  int find(std::initializer_list<const char*> names) const {
    for (size_t i = 0; i < props.size(); ++i)
      for (const char* n : names)
        if (props[i].name == n && !props[i].is_list) return static_cast<int>(i);
    return -1;
  }
};

struct Header {
  Format format = Format::Ascii;
  std::vector<Element> elements;
  size_t data_start = 0;
};

// Every error names the file and points at the scene parameter that asked for it.
struct Context {
  const std::string& path;
  const FileLoc& loc;
  [[noreturn]] void fail(const std::string& msg) const {
    throw Error(loc, fmt::format("PLY file '{}': {}", path, msg));
  }
};

bool parse_scalar_type(const std::string& s, Scalar& t) {
  static const std::pair<const char*, Scalar> names[] = {
      {"char", Scalar::Int8},       {"int8", Scalar::Int8},       {"uchar", Scalar::UInt8},
      {"uint8", Scalar::UInt8},     {"short", Scalar::Int16},     {"int16", Scalar::Int16},
      {"ushort", Scalar::UInt16},   {"uint16", Scalar::UInt16},   {"int", Scalar::Int32},
      {"int32", Scalar::Int32},     {"uint", Scalar::UInt32},     {"uint32", Scalar::UInt32},
      {"float", Scalar::Float32},   {"float32", Scalar::Float32}, {"double", Scalar::Float64},
      {"float64", Scalar::Float64},
  };
  for (const auto& [name, type] : names)
    if (s == name) {
      t = type;
      return true;
    }
  return false;
}

size_t size_of(Scalar t) {
  switch (t) {
    case Scalar::Int8:
    case Scalar::UInt8: return 1;
    case Scalar::Int16:
    case Scalar::UInt16: return 2;
    case Scalar::Int32:
    case Scalar::UInt32:
    case Scalar::Float32: return 4;
    case Scalar::Float64: return 8;
  }
  return 0;
}

Scalar scalar_type(const std::string& s, const Context& ctx) {
  Scalar t;
  if (!parse_scalar_type(s, t)) ctx.fail(fmt::format("unknown property type '{}'", s));
  return t;
}

Property parse_property(std::istringstream& in, const Context& ctx) {
  Property p;
  std::string first;
  in >> first;
  if (first == "list") {
    std::string count_type, item_type;
    in >> count_type >> item_type >> p.name;
    p.is_list = true;
    p.count_type = scalar_type(count_type, ctx);
    p.type = scalar_type(item_type, ctx);
    if (p.count_type == Scalar::Float32 || p.count_type == Scalar::Float64)
      ctx.fail(fmt::format("list property '{}' has a floating-point count type", p.name));
  } else {
    in >> p.name;
    p.type = scalar_type(first, ctx);
  }
  if (p.name.empty()) ctx.fail("property without a name in the header");
  return p;
}

Format parse_format(const std::string& s, const Context& ctx) {
  if (s == "ascii") return Format::Ascii;
  if (s == "binary_little_endian") return Format::BinaryLittleEndian;
  if (s == "binary_big_endian") return Format::BinaryBigEndian;
  ctx.fail(fmt::format("unknown format '{}'", s));
}

// Reads one header line (without its "\n" or "\r\n"); false at the end of the data.
bool next_line(const std::string& data, size_t& pos, std::string& line) {
  if (pos >= data.size()) return false;
  size_t end = data.find('\n', pos);
  if (end == std::string::npos) end = data.size();
  line = data.substr(pos, end - pos);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  pos = std::min(end + 1, data.size());
  return true;
}

void parse_header_line(const std::string& line, Header& h, bool& has_format, const Context& ctx) {
  std::istringstream in(line);
  std::string keyword;
  in >> keyword;
  if (keyword.empty() || keyword == "comment" || keyword == "obj_info") return;
  if (keyword == "format") {
    std::string f;
    in >> f;
    h.format = parse_format(f, ctx);
    has_format = true;
  } else if (keyword == "element") {
    Element e;
    if (!(in >> e.name >> e.count)) ctx.fail(fmt::format("bad header line '{}'", line));
    h.elements.push_back(std::move(e));
  } else if (keyword == "property") {
    if (h.elements.empty()) ctx.fail("property before any element in the header");
    h.elements.back().props.push_back(parse_property(in, ctx));
  } else {
    ctx.fail(fmt::format("unknown header line '{}'", line));
  }
}

Header parse_header(const std::string& data, const Context& ctx) {
  Header h;
  size_t pos = 0;
  std::string line;
  if (!next_line(data, pos, line) || line != "ply")
    ctx.fail("not a PLY file (no 'ply' first line)");
  bool has_format = false;
  while (next_line(data, pos, line)) {
    if (line == "end_header") {
      if (!has_format) ctx.fail("the header has no format line");
      h.data_start = pos;
      return h;
    }
    parse_header_line(line, h, has_format, ctx);
  }
  ctx.fail("the header has no end_header line");
}

// Reads the values of the body one at a time, in whichever format the file uses.
class DataReader {
 public:
  DataReader(const std::string& data, size_t pos, Format format, const Context& ctx)
      : data_(data), pos_(pos), format_(format), ctx_(ctx) {}

  double read(Scalar t) { return format_ == Format::Ascii ? read_ascii() : read_binary(t); }

  // A list's length, checked so that a corrupt count cannot run away: its items must fit in the
  // bytes that are left (each binary item takes its type's size; each ascii one a character and a
  // separator, but the file's last), so a 4-byte count cannot make the caller reserve gigabytes
  // for a list the file cannot hold.
  size_t read_count(const Property& p) {
    double n = read(p.count_type);
    // Compared, never cast: a NaN count (float count types are refused, but ascii data may spell it
    // "nan") fails the first test, an infinite one the size test below.
    if (!(n >= 0) || n != std::floor(n))
      ctx_.fail(fmt::format("bad list length {} in property '{}'", n, p.name));
    size_t left = data_.size() - pos_;
    size_t fits = format_ == Format::Ascii ? (left + 1) / 2 : left / size_of(p.type);
    if (n > static_cast<double>(fits))
      ctx_.fail(fmt::format("truncated data (the file ends early): list property '{}' claims {} items, more "
                            "than the {} bytes left can hold",
                            p.name, n, left));
    return static_cast<size_t>(n);
  }

  void skip(const Property& p) {
    size_t n = p.is_list ? read_count(p) : 1;
    for (size_t i = 0; i < n; ++i) read(p.type);
  }

 private:
  double read_binary(Scalar t) {
    size_t n = size_of(t);
    if (pos_ + n > data_.size()) ctx_.fail("truncated data (the file ends early)");
    unsigned char b[8];
    std::memcpy(b, data_.data() + pos_, n);
    pos_ += n;
    bool file_little = format_ == Format::BinaryLittleEndian;
    if (file_little != (std::endian::native == std::endian::little)) std::reverse(b, b + n);
    return decode(t, b);
  }

  static double decode(Scalar t, const unsigned char* b) {
    switch (t) {
      case Scalar::Int8: return as<int8_t>(b);
      case Scalar::UInt8: return as<uint8_t>(b);
      case Scalar::Int16: return as<int16_t>(b);
      case Scalar::UInt16: return as<uint16_t>(b);
      case Scalar::Int32: return as<int32_t>(b);
      case Scalar::UInt32: return as<uint32_t>(b);
      case Scalar::Float32: return as<float>(b);
      case Scalar::Float64: return as<double>(b);
    }
    return 0.0;
  }

  template <typename T>
  static double as(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof(T));
    return static_cast<double>(v);
  }

  double read_ascii() {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    size_t start = pos_;
    while (pos_ < data_.size() && !std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    if (start == pos_) ctx_.fail("truncated data (the file ends early)");
    double v = 0.0;
    auto [end, ec] = std::from_chars(data_.data() + start, data_.data() + pos_, v);
    if (ec != std::errc() || end != data_.data() + pos_)
      ctx_.fail(fmt::format("bad number '{}' in the data", data_.substr(start, pos_ - start)));
    return v;
  }

  const std::string& data_;
  size_t pos_;
  Format format_;
  const Context& ctx_;
};

void read_vertices(const Element& e, DataReader& in, TriangleMeshData& mesh, size_t size_bound) {
  int x = e.find({"x"}), y = e.find({"y"}), z = e.find({"z"});
  int nx = e.find({"nx"}), ny = e.find({"ny"}), nz = e.find({"nz"});
  int u = e.find({"u", "s", "texture_u", "texture_s"});
  int v = e.find({"v", "t", "texture_v", "texture_t"});
  bool normals = nx >= 0 && ny >= 0 && nz >= 0, uvs = u >= 0 && v >= 0;
  size_t reserve = std::min(e.count, size_bound);
  mesh.P.reserve(reserve);
  if (normals) mesh.N.reserve(reserve);
  if (uvs) mesh.uv.reserve(reserve);
  std::vector<double> row(e.props.size());
  for (size_t i = 0; i < e.count; ++i) {
    for (size_t k = 0; k < e.props.size(); ++k) {
      if (e.props[k].is_list)
        in.skip(e.props[k]);
      else
        row[k] = in.read(e.props[k].type);
    }
    mesh.P.emplace_back(row[x], row[y], row[z]);
    if (normals) mesh.N.emplace_back(row[nx], row[ny], row[nz]);
    if (uvs) mesh.uv.emplace_back(row[u], row[v]);
  }
}

int find_index_list(const Element& e) {
  for (size_t i = 0; i < e.props.size(); ++i)
    if (e.props[i].is_list &&
        (e.props[i].name == "vertex_indices" || e.props[i].name == "vertex_index"))
      return static_cast<int>(i);
  return -1;
}

// Splits a polygon into a fan of triangles around its first vertex (a quad gives 0 1 2, 0 2 3).
void add_polygon(const std::vector<int>& poly, std::vector<int>& indices) {
  for (size_t k = 1; k + 1 < poly.size(); ++k)
    indices.insert(indices.end(), {poly[0], poly[k], poly[k + 1]});
}

// The value of integer `v` of type `t` with its bytes in the other order.
double byte_swapped(Scalar t, double v) {
  unsigned char b[8];
  auto swap = [&](auto x) {
    std::memcpy(b, &x, sizeof x);
    std::reverse(b, b + sizeof x);
    std::memcpy(&x, b, sizeof x);
    return static_cast<double>(x);
  };
  switch (t) {
    case Scalar::Int16: return swap(static_cast<int16_t>(v));
    case Scalar::UInt16: return swap(static_cast<uint16_t>(v));
    case Scalar::Int32: return swap(static_cast<int32_t>(v));
    case Scalar::UInt32: return swap(static_cast<uint32_t>(v));
    default: return v;  // one byte, or not an integer type
  }
}

// For a bad vertex index in a binary file: whether the other byte order would have made it a good
// one, the signature of a file whose header names the wrong endianness.
std::string endianness_hint(Format format, Scalar t, double value, size_t vertex_count) {
  if (format == Format::Ascii || size_of(t) == 1 || value != std::floor(value)) return "";
  double other = byte_swapped(t, value);
  if (other < 0 || other >= static_cast<double>(vertex_count)) return "";
  return fmt::format("; read in the other byte order it would be {}, a valid index: the header says {}, but the "
                     "data look {} (was the file written with the wrong endianness?)",
                     other, format == Format::BinaryLittleEndian ? "binary_little_endian" : "binary_big_endian",
                     format == Format::BinaryLittleEndian ? "big-endian" : "little-endian");
}

// Returns the type of the index list, for check_mesh()'s endianness hint.
Scalar read_faces(const Element& e, DataReader& in, TriangleMeshData& mesh, Format format, const Context& ctx) {
  int list = find_index_list(e);
  if (list < 0) ctx.fail("the face element has no vertex_indices list");
  size_t vertices = mesh.P.empty() ? SIZE_MAX : mesh.P.size();  // known when the vertices came first
  std::vector<int> poly;
  for (size_t i = 0; i < e.count; ++i) {
    for (size_t k = 0; k < e.props.size(); ++k) {
      const Property& p = e.props[k];
      if (static_cast<int>(k) != list) {
        in.skip(p);
        continue;
      }
      poly.resize(in.read_count(p));
      for (int& idx : poly) {
        double d = in.read(p.type);
        if (!(d >= 0 && d <= INT_MAX))  // NaN too (a float index type): it is never cast
          ctx.fail(fmt::format("vertex index {} out of range in face {}{}", d, i,
                               endianness_hint(format, p.type, d, vertices)));
        if (d != std::floor(d))
          ctx.fail(fmt::format("vertex index {} in face {} is not an integer", d, i));
        idx = static_cast<int>(d);
      }
      add_polygon(poly, mesh.indices);  // faces with fewer than 3 vertices add nothing
    }
  }
  return e.props[list].type;
}

void check_mesh(const TriangleMeshData& mesh, bool has_vertices, Format format, Scalar index_type,
                const Context& ctx) {
  if (!has_vertices) ctx.fail("no vertex element with x, y and z properties");
  if (mesh.P.empty()) ctx.fail("the mesh has no vertices");
  if (mesh.indices.empty()) ctx.fail("the mesh has no faces");
  for (int idx : mesh.indices)
    if (idx < 0 || static_cast<size_t>(idx) >= mesh.P.size())
      ctx.fail(fmt::format("vertex index {} out of range (the mesh has {} vertices){}", idx, mesh.P.size(),
                           endianness_hint(format, index_type, idx, mesh.P.size())));
}

// Only regular files, read up to their size (util/input_file.h): a link to /dev/zero or a FIFO
// is refused instead of read forever.
std::string read_file_bytes(const std::string& path, const Context& ctx) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) ctx.fail("cannot open the file");
  std::string problem = input_file_problem(path);
  if (!problem.empty()) ctx.fail(fmt::format("cannot open the file: {}", problem));
  try {
    return read_input_file(path, "the file");
  } catch (const Error& e) {
    ctx.fail(e.what());
  }
}

}  // namespace

TriangleMeshData read_ply(const std::string& path, const FileLoc& loc) {
  Context ctx{path, loc};
  std::string data = read_file_bytes(path, ctx);
  Header h = parse_header(data, ctx);
  // Every item of an element with properties takes at least a byte: a count beyond the data is a
  // corrupt header, refused before a loop of that many reads (or a reservation) starts.
  for (const Element& e : h.elements)
    if (e.count > data.size() - h.data_start)
      ctx.fail(fmt::format("the header declares {} '{}' items, more than the {} bytes after the header can hold",
                           e.count, e.name, data.size() - h.data_start));
  DataReader in(data, h.data_start, h.format, ctx);
  TriangleMeshData mesh;
  bool has_vertices = false;
  Scalar index_type = Scalar::Int32;
  for (const Element& e : h.elements) {
    bool positions = e.find({"x"}) >= 0 && e.find({"y"}) >= 0 && e.find({"z"}) >= 0;
    if (e.name == "vertex" && positions && !has_vertices) {
      read_vertices(e, in, mesh, data.size());
      has_vertices = true;
    } else if (e.name == "face") {
      index_type = read_faces(e, in, mesh, h.format, ctx);
    } else {
      for (size_t i = 0; i < e.count; ++i)
        for (const Property& p : e.props) in.skip(p);
    }
  }
  check_mesh(mesh, has_vertices, h.format, index_type, ctx);
  return mesh;
}

}  // namespace penumbra
