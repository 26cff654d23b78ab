#pragma once
// The image's k-space (its discrete Fourier transform, FFTW in single precision, as scanners
// reconstruct), where MR acquisition artefacts arise: truncation (Gibbs ringing), spikes and
// phase-encoding errors (ghosts) act on k-space samples and come back to the image by the
// inverse transform.
#include <array>
#include <complex>
#include <cstdint>
#include <vector>

#include "raster/volume.hpp"

namespace angiosynth {

class KSpace {
 public:
  explicit KSpace(const Volume<float>& image);  // the forward transform of the image
  // Signed frequency index (cycles per field of view) of FFT index n along an axis of size N.
  static std::int64_t frequency(std::int64_t n, std::int64_t size) { return n <= (size - 1) / 2 ? n : n - size; }
  std::complex<float>& at(std::int64_t i, std::int64_t j, std::int64_t k) { return data_[std::size_t(i + dims_[0] * (j + dims_[1] * k))]; }
  const std::array<std::int32_t, 3>& dims() const { return dims_; }
  // Visits every sample with its signed frequency along each axis.
  template <class F>
  void forEachSample(F&& f) {
    for (std::int64_t k = 0; k < dims_[2]; ++k)
      for (std::int64_t j = 0; j < dims_[1]; ++j)
        for (std::int64_t i = 0; i < dims_[0]; ++i)
          f(std::array<std::int64_t, 3>{frequency(i, dims_[0]), frequency(j, dims_[1]), frequency(k, dims_[2])}, at(i, j, k));
  }
  // The inverse transform into `image`, in place (the k-space is spent): its real part, or its
  // magnitude (an MR magnitude image).
  void toImage(Volume<float>& image, bool magnitude) &&;

 private:
  std::array<std::int32_t, 3> dims_;
  std::vector<std::complex<float>> data_;
};

// What a k-space holds per voxel while an effect runs (the memory estimate).
constexpr std::uint64_t kKSpaceBytesPerVoxel = sizeof(std::complex<float>);

}  // namespace angiosynth
