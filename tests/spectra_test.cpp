// Spectra in an RGB renderer (core/src/spectra, parser/spectrum_params.cpp). The independent side
// reads data/spectra/*.csv itself and integrates by a plain Riemann sum at whole nanometres (pbrt-v4's
// own SpectrumToXYZ), with its own XYZ -> Rec.709 matrix; the runtime integrates the piecewise-linear
// products exactly from its compiled-in tables. Scenes go through the real parser.
#include <fmt/core.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "parser/scene_description.h"
#include "spectra/named_spectra.h"
#include "spectra/spectrum.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const fs::path kData = fs::path(PENUMBRA_SOURCE_DIR) / "data" / "spectra";

// ---- The independent side: CSV files, linear interpolation, Riemann sums, own matrix ------------

struct Table {
  std::vector<double> lambda;
  std::vector<std::vector<double>> columns;
  double at(double l, size_t c = 0) const {
    if (l < lambda.front() || l > lambda.back()) return 0.0;
    size_t i = 0;
    while (i + 2 < lambda.size() && lambda[i + 1] <= l) ++i;
    double t = (l - lambda[i]) / (lambda[i + 1] - lambda[i]);
    return columns[c][i] + t * (columns[c][i + 1] - columns[c][i]);
  }
};

Table read_csv(const std::string& name) {
  std::ifstream in(kData / (name + ".csv"));
  EXPECT_TRUE(in) << name;
  Table t;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream row(line);
    double l, v;
    row >> l;
    t.lambda.push_back(l);
    for (size_t c = 0; row >> v; ++c) {
      if (t.columns.size() <= c) t.columns.emplace_back();
      t.columns[c].push_back(v);
    }
  }
  return t;
}

using Vec = std::array<double, 3>;
using Mat = std::array<Vec, 3>;  // rows

Vec mul(const Mat& m, const Vec& v) {
  return {m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2], m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
          m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2]};
}

Mat inverse(const Mat& m) {
  double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
               m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  Mat r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      // cofactor of (j, i)
      int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
      r[i][j] = (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]) / det;
    }
  return r;
}

struct Reference {
  Table cmf = read_csv("cie1931-2deg-cmf");
  Table d65 = read_csv("stdillum-D65");
  Mat xyz_to_rgb;
  double white_y = 0.0;

  Reference() {
    Vec w = xyz([](double) { return 1.0; }, true);
    white_y = w[1];
    const double xy[3][2] = {{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}};
    Mat p;  // columns are primaries
    for (int c = 0; c < 3; ++c) {
      p[0][c] = xy[c][0] / xy[c][1];
      p[1][c] = 1.0;
      p[2][c] = (1 - xy[c][0] - xy[c][1]) / xy[c][1];
    }
    Vec white = {w[0] / w[1], 1.0, w[2] / w[1]};
    Vec s = mul(inverse(p), white);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) p[r][c] *= s[c];
    xyz_to_rgb = inverse(p);
  }

  // Riemann sum over whole nanometres 360..830.
  template <class F>
  Vec xyz(F s, bool under_d65) const {
    Vec sum{0, 0, 0};
    for (int l = 360; l <= 830; ++l) {
      double w = s(l) * (under_d65 ? d65.at(l) : 1.0);
      for (int c = 0; c < 3; ++c) sum[c] += w * cmf.columns[c][l - 360];
    }
    return sum;
  }
  template <class F>
  Vec reflectance(F s) const {
    Vec v = xyz(s, true);
    for (double& x : v) x /= white_y;
    return mul(xyz_to_rgb, v);
  }
  template <class F>
  Vec emission(F s) const {
    Vec v = xyz(s, false);
    double y = v[1];
    for (double& x : v) x /= y;
    return mul(xyz_to_rgb, v);
  }
};

const Reference& ref() {
  static const Reference r;
  return r;
}

// Largest channel difference relative to the largest channel (colours with a near-zero channel,
// like gold's blue reflectance, would otherwise be judged by rounding noise).
double max_rel_diff(const Rgb& a, const Vec& b) {
  double d = 0.0, scale = std::max({std::abs(b[0]), std::abs(b[1]), std::abs(b[2]), 1e-6});
  for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(a[c] - b[c]) / scale);
  return d;
}

// The RGB the parser gives a material's or a light's spectrum parameter.
Rgb parsed_rgb(const std::string& directive_and_param) {
  SceneDescription d = parse_scene_string("WorldBegin\n" + directive_and_param + "\n", "scene.pbrt");
  const ParamSet& p = !d.materials.empty() ? d.materials[0].params : d.lights[0].params;
  const Param& q = p.params().at(0);
  EXPECT_EQ(q.numbers.size(), 3u);
  return Rgb(q.numbers[0], q.numbers[1], q.numbers[2]);
}

// ---- Named spectra against the independent derivation ------------------------------------------

// Measured difference between the exact integration and the Riemann sum (relative to the largest
// channel): at most 1.1e-4 for 35 of the 36 tables, 1.55e-3 for metal-TiO2-k, whose few samples put
// kinks between whole nanometres where its values are tiny. 2e-3 is five times below the 1 % a
// wrong table, matrix or normalisation would show (the negative control below checks that).
constexpr double kTolerance = 2e-3;

TEST(Spectra, EveryNamedSpectrumMatchesARiemannSumOverTheCieTables) {
  std::vector<std::string> names = spectra::named_spectrum_names();
  ASSERT_EQ(names.size(), 36u);  // 7 glasses, 7 metals x (eta, k), D50, D65, A, F1..F12
  double worst = 0.0;
  for (const auto& name : names) {
    double d_last = 0.0;
    Table t = read_csv(name);
    auto s = [&](double l) { return t.at(l); };
    std::optional<spectra::Spectrum> named = spectra::named_spectrum(name);
    ASSERT_TRUE(named) << name;
    if (name.rfind("stdillum-", 0) == 0) {
      Rgb e = spectra::emission_to_rgb(*named);
      double d = max_rel_diff(e, ref().emission(s));
      worst = std::max(worst, d);
      d_last = d;
      EXPECT_LT(d, kTolerance) << name << " emission";
    } else {
      Rgb r = spectra::reflectance_to_rgb(*named);
      double d = max_rel_diff(r, ref().reflectance(s));
      worst = std::max(worst, d);
      d_last = d;
      EXPECT_LT(d, kTolerance) << name << " reflectance";
      // Negative control: a 1 % error in the data would be seen (MgO's k is 0 everywhere).
      auto s_off = [&](double l) { return 1.01 * t.at(l); };
      if (name != "metal-MgO-k") EXPECT_GT(max_rel_diff(r, ref().reflectance(s_off)), 4 * kTolerance) << name;
    }
    std::printf("%-16s %.2e\n", name.c_str(), d_last);
  }
  std::printf("worst relative difference, exact integration vs Riemann sum: %.2e\n", worst);
}

TEST(Spectra, ParserGivesTheSameRgbAsTheIndependentDerivation) {
  Table au_eta = read_csv("metal-Au-eta"), au_k = read_csv("metal-Au-k");
  Rgb eta = parsed_rgb(R"(Material "conductor" "spectrum eta" "metal-Au-eta")");
  Rgb k = parsed_rgb(R"(Material "conductor" "spectrum k" "metal-Au-k")");
  EXPECT_LT(max_rel_diff(eta, ref().reflectance([&](double l) { return au_eta.at(l); })), kTolerance);
  EXPECT_LT(max_rel_diff(k, ref().reflectance([&](double l) { return au_k.at(l); })), kTolerance);
  // Gold: small real part in red, large in blue; k falls from red to blue.
  EXPECT_LT(eta.r, eta.g);
  EXPECT_LT(eta.g, eta.b);
  EXPECT_GT(k.r, k.g);
  EXPECT_GT(k.g, k.b);
}

TEST(Spectra, ConstantReflectanceIsGreyAndD65EmissionIsWhite) {
  Rgb one = spectra::reflectance_to_rgb(spectra::Spectrum({300, 900}, {1, 1}));
  EXPECT_NEAR(one.r, 1.f, 1e-6f);
  EXPECT_NEAR(one.g, 1.f, 1e-6f);
  EXPECT_NEAR(one.b, 1.f, 1e-6f);
  Rgb half = parsed_rgb(R"(Material "diffuse" "spectrum reflectance" [ 300 0.5 800 0.5 ])");
  EXPECT_NEAR(half.r, 0.5f, 1e-6f);
  EXPECT_NEAR(half.g, 0.5f, 1e-6f);
  EXPECT_NEAR(half.b, 0.5f, 1e-6f);
  Rgb white = parsed_rgb(R"(LightSource "point" "spectrum I" "stdillum-D65")");
  EXPECT_NEAR(white.r, 1.f, 1e-6f);
  EXPECT_NEAR(white.g, 1.f, 1e-6f);
  EXPECT_NEAR(white.b, 1.f, 1e-6f);
  // An emission spectrum is brought to luminance 1, whatever its scale (pbrt-v4 normalises light
  // spectra photometrically); "rgb" emission stays as given.
  Rgb a = parsed_rgb(R"(LightSource "point" "spectrum I" [ 400 7 700 7 ])");
  EXPECT_NEAR(luminance(a), 1.f, 2e-4f);  // color.h's rounded Rec.709 weights
  Rgb given = parsed_rgb(R"(LightSource "point" "rgb I" [ 2 3 4 ])");
  EXPECT_EQ(given, Rgb(2, 3, 4));
  // Three numbers stay RGB (Penumbra's shorthand for "rgb").
  EXPECT_EQ(parsed_rgb(R"(Material "diffuse" "spectrum reflectance" [ 0.1 0.2 0.3 ])"), Rgb(0.1f, 0.2f, 0.3f));
}

TEST(Spectra, IlluminantAIsWarmAndItsChromaticityIsTheCieValue) {
  // CIE 15: illuminant A at x = 0.44757, y = 0.40745 (2-degree observer).
  Table a = read_csv("stdillum-A");
  Vec xyz = ref().xyz([&](double l) { return a.at(l); }, false);
  double sum = xyz[0] + xyz[1] + xyz[2];
  EXPECT_NEAR(xyz[0] / sum, 0.44757, 5e-5);
  EXPECT_NEAR(xyz[1] / sum, 0.40745, 5e-5);
  Rgb rgb = parsed_rgb(R"(LightSource "point" "spectrum I" "stdillum-A")");
  EXPECT_GT(rgb.r, rgb.g);
  EXPECT_GT(rgb.g, rgb.b);
}

// ---- Blackbodies ---------------------------------------------------------------------------------

// Chromaticity of the Planckian locus by Kim et al.'s cubic splines (2002, the formula behind many
// colour-temperature tools): an independent closed form, accurate to about 1e-3 in x and y.
std::pair<double, double> planckian_xy(double t) {
  double x = t <= 4000 ? -0.2661239e9 / (t * t * t) - 0.2343589e6 / (t * t) + 0.8776956e3 / t + 0.179910
                       : -3.0258469e9 / (t * t * t) + 2.1070379e6 / (t * t) + 0.2226347e3 / t + 0.240390;
  double y = t <= 2222   ? -1.1063814 * x * x * x - 1.34811020 * x * x + 2.18555832 * x - 0.20219683
             : t <= 4000 ? -0.9549476 * x * x * x - 1.37418593 * x * x + 2.09137015 * x - 0.16748867
                         : 3.0817580 * x * x * x - 5.87338670 * x * x + 3.75112997 * x - 0.37001483;
  return {x, y};
}

TEST(Spectra, BlackbodyChromaticityFollowsThePlanckianLocus) {
  for (double t : {2000.0, 2700.0, 3500.0, 5000.0, 6504.0, 9000.0, 15000.0}) {
    glm::dvec3 xyz = spectra::spectrum_to_xyz(spectra::Spectrum::blackbody(t), false);
    double sum = xyz.x + xyz.y + xyz.z;
    auto [x, y] = planckian_xy(t);
    EXPECT_NEAR(xyz.x / sum, x, 1.5e-3) << t;
    EXPECT_NEAR(xyz.y / sum, y, 1.5e-3) << t;
  }
  // 6504 K lies 0.006 from D65 in xy (D65 sits just above the locus): nearly white in Rec.709.
  Rgb c = parsed_rgb(R"(LightSource "point" "blackbody I" [ 6504 ])");
  EXPECT_NEAR(c.r, 1.f, 0.05f);
  EXPECT_NEAR(c.g, 1.f, 0.05f);
  EXPECT_NEAR(c.b, 1.f, 0.05f);
  Rgb warm = parsed_rgb(R"(LightSource "point" "blackbody I" [ 2700 ])");
  Rgb cold = parsed_rgb(R"(LightSource "point" "blackbody I" [ 12000 ])");
  EXPECT_GT(warm.r, warm.g);
  EXPECT_GT(warm.g, warm.b);
  EXPECT_LT(cold.r, cold.g);
  EXPECT_LT(cold.g, cold.b);
}

TEST(Spectra, BlackbodyIsNormalisedToItsPeak) {
  for (double t : {1000.0, 3000.0, 6500.0}) {
    spectra::Spectrum b = spectra::Spectrum::blackbody(t);
    double peak = 2.8977721e-3 / t * 1e9;  // Wien's displacement law, nm
    EXPECT_NEAR(b(peak), 1.0, 1e-12);
    EXPECT_LT(b(peak * 0.98), 1.0);
    EXPECT_LT(b(peak * 1.02), 1.0);
  }
  // As a reflectance-like parameter pbrt-v4 uses the peak-normalised spectrum as it is.
  Rgb r = parsed_rgb(R"(Material "diffuse" "blackbody reflectance" [ 5000 ])");
  Vec expect = ref().reflectance([](double l) { return spectra::Spectrum::blackbody(5000)(l); });
  EXPECT_LT(max_rel_diff(r, expect), kTolerance);
}

// ---- Dielectric IOR: one value ---------------------------------------------------------------------

TEST(Spectra, DielectricEtaIsTheLuminanceWeightedMean) {
  Table bk7 = read_csv("glass-BK7");
  const Table& cmf = ref().cmf;
  double num = 0, den = 0;
  for (int l = 360; l <= 830; ++l) {
    double w = ref().d65.at(l) * cmf.columns[1][l - 360];
    num += bk7.at(l) * w;
    den += w;
  }
  SceneDescription d = parse_scene_string("WorldBegin\nMaterial \"dielectric\" \"spectrum eta\" \"glass-BK7\"\n");
  ParamSet p = d.materials[0].params;
  const ParamSpec spec[] = {{"float|spectrum", "eta", "1.5", ""}};
  p.validate(spec, "bsdf 'dielectric'");
  // 1e-4: color.h's luminance weights are Rec.709's rounded to 4 digits.
  EXPECT_NEAR(p.get_float("eta"), num / den, 1e-4);
  EXPECT_NEAR(num / den, 1.5184, 1e-3);  // BK7: n = 1.5168 at 587.6 nm, 1.5185 at 550 nm
  // A float eta stays as given.
  SceneDescription f = parse_scene_string("WorldBegin\nMaterial \"dielectric\" \"float eta\" 1.33\n");
  ParamSet q = f.materials[0].params;
  q.validate(spec, "bsdf 'dielectric'");
  EXPECT_FLOAT_EQ(q.get_float("eta"), 1.33f);
}

// ---- Spectrum files ---------------------------------------------------------------------------------

class TempDir {
 public:
  TempDir() {
    dir_ = fs::temp_directory_path() / ("penumbra-spectra-" + std::to_string(::getpid()));
    fs::create_directories(dir_ / "spd");
  }
  ~TempDir() { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }

 private:
  fs::path dir_;
};

TEST(Spectra, SpdFilesAreReadRelativeToTheSceneFile) {
  TempDir dir;
  dir.write("spd/ramp.spd", "# a ramp\n400 0.2   # blue end\n550 0.5\n700 0.8\n");
  std::string scene =
      dir.write("scene.pbrt", "WorldBegin\nMaterial \"diffuse\" \"spectrum reflectance\" \"spd/ramp.spd\"\n");
  SceneDescription d = parse_scene_file(scene);
  const Param& p = d.materials[0].params.params().at(0);
  Rgb from_file(p.numbers[0], p.numbers[1], p.numbers[2]);
  Rgb inline_pairs = parsed_rgb(R"(Material "diffuse" "spectrum reflectance" [ 400 0.2 550 0.5 700 0.8 ])");
  EXPECT_EQ(from_file, inline_pairs);
  EXPECT_LT(from_file.b, from_file.g);
  EXPECT_LT(from_file.g, from_file.r);

  dir.write("spd/bad.spd", "400 0.2\n550 oops\n");
  std::string bad = dir.write("bad.pbrt", "WorldBegin\nMaterial \"diffuse\" \"spectrum reflectance\" \"spd/bad.spd\"\n");
  try {
    parse_scene_file(bad);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_THAT(e.formatted(), HasSubstr("bad.pbrt:2:20: error: spectrum file"));
    EXPECT_THAT(e.formatted(), HasSubstr("line 2: 'oops' is not a number"));
  }
  dir.write("spd/odd.spd", "400 0.2 550\n");
  std::string odd = dir.write("odd.pbrt", "WorldBegin\nMaterial \"diffuse\" \"spectrum reflectance\" \"spd/odd.spd\"\n");
  try {
    parse_scene_file(odd);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_THAT(e.formatted(), HasSubstr("must hold (wavelength, value) pairs, got 3 numbers"));
  }
}

}  // namespace
}  // namespace penumbra
