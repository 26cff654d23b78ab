#include "degrade/kspace.hpp"

#include <fftw3.h>

#include <cmath>
#include <mutex>

namespace angiosynth {
namespace {

// FFTW's planner is not thread-safe; samples are degraded on several threads. FFTW_ESTIMATE
// plans without timing runs and FFTW_UNALIGNED without regard to where the array lies, so the
// same grid always gets the same plan: the same bytes.
std::mutex& plannerMutex() {
  static std::mutex m;
  return m;
}

void transform(std::vector<std::complex<float>>& data, const std::array<std::int32_t, 3>& dims, int sign) {
  auto* p = reinterpret_cast<fftwf_complex*>(data.data());
  fftwf_plan plan;
  {
    const std::lock_guard<std::mutex> lock(plannerMutex());
    // Row-major in FFTW's order: z slowest, x fastest, as the volume stores its voxels.
    plan = fftwf_plan_dft_3d(dims[2], dims[1], dims[0], p, p, sign, FFTW_ESTIMATE | FFTW_UNALIGNED);
  }
  fftwf_execute(plan);
  const std::lock_guard<std::mutex> lock(plannerMutex());
  fftwf_destroy_plan(plan);
}

}  // namespace

KSpace::KSpace(const Volume<float>& image) : dims_(image.grid.dims), data_(image.data.begin(), image.data.end()) {
  transform(data_, dims_, FFTW_FORWARD);
}

void KSpace::toImage(Volume<float>& image, bool magnitude) && {
  transform(data_, dims_, FFTW_BACKWARD);
  const double n = double(data_.size());  // FFTW's inverse is unnormalised
  for (std::size_t v = 0; v < data_.size(); ++v) image.data[v] = float((magnitude ? double(std::abs(data_[v])) : double(data_[v].real())) / n);
  data_.clear();
  data_.shrink_to_fit();
}

}  // namespace angiosynth
