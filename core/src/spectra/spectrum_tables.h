// The measured spectra compiled into the runtime: the CIE 1931 2-degree colour-matching functions
// and pbrt-v4's named spectra. The numbers live in data/spectra/*.csv (sources in the README there);
// cmake/EmbedSpectra.cmake generates the definitions at build time.
#pragma once

namespace penumbra::spectra {

/// x-bar, y-bar, z-bar sampled every 1 nm from `first_lambda` (count samples).
struct CmfTable {
  int first_lambda;
  int count;
  const float* x;
  const float* y;
  const float* z;
};

/// One measured spectrum: `count` (wavelength in nm, value) samples, wavelengths increasing.
struct TabulatedSpectrum {
  const char* name;
  int count;
  const float* lambda;
  const float* value;
};

extern const CmfTable kCmf;
extern const TabulatedSpectrum kNamedTables[];
extern const int kNamedTableCount;

}  // namespace penumbra::spectra
