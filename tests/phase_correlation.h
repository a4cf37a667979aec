// Phase correlation of two image windows (tests): the shift that carries a pattern in the first
// window onto the second, to a fraction of a pixel. The cross-power spectrum of the two
// Hann-windowed windows, normalised to unit magnitude and transformed back, peaks at the shift;
// a parabola through the peak and its neighbours places it between pixels.
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstddef>
#include <numbers>
#include <vector>

#include <glm/vec2.hpp>

namespace siviflow::testing {

using Complex = std::complex<double>;

// In-place radix-2 FFT of `n` values `stride` apart (n a power of two); inverse without the 1/n.
inline void fft(Complex* data, size_t n, size_t stride, bool inverse) {
  for (size_t i = 1, j = 0; i < n; ++i) {  // bit-reversal permutation
    size_t bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) std::swap(data[i * stride], data[j * stride]);
  }
  for (size_t length = 2; length <= n; length <<= 1) {
    const double angle = 2.0 * std::numbers::pi / double(length) * (inverse ? 1.0 : -1.0);
    const Complex step(std::cos(angle), std::sin(angle));
    for (size_t start = 0; start < n; start += length) {
      Complex w(1.0, 0.0);
      for (size_t k = 0; k < length / 2; ++k) {
        Complex& a = data[(start + k) * stride];
        Complex& b = data[(start + k + length / 2) * stride];
        const Complex t = b * w;
        b = a - t;
        a += t;
        w *= step;
      }
    }
  }
}

// 2-D FFT of a size x size image, row-major.
inline void fft2(std::vector<Complex>& image, size_t size, bool inverse) {
  for (size_t y = 0; y < size; ++y) fft(&image[y * size], size, 1, inverse);
  for (size_t x = 0; x < size; ++x) fft(&image[x], size, size, inverse);
}

// Cross-power bins below this fraction of the strongest are left out.
inline constexpr double kLeakageFloor = 0.01;

// A size x size window of one or more channels (planes of the same window), row-major.
struct Window {
  size_t size = 0;
  std::vector<std::vector<double>> channels;
};

// The shift d (pixels, x right, y down) with second(p + d) ~ first(p); `peak` receives the
// correlation peak's height (higher the more alike the shifted windows are). The fixed window
// pulls large shifts a little towards 0 (5 % at a sixth of the window): for accuracy, measure
// again with the second window moved by the whole pixels of the first estimate.
inline glm::dvec2 phase_correlation_shift(const Window& first, const Window& second,
                                          double* peak = nullptr) {
  const size_t n = first.size;
  std::vector<Complex> cross(n * n, Complex(0.0, 0.0));
  const auto hann = [n](size_t i) { return 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * (i + 0.5) / n); };
  for (size_t c = 0; c < first.channels.size(); ++c) {
    std::vector<Complex> a(n * n), b(n * n);
    double mean_a = 0.0, mean_b = 0.0;
    for (size_t i = 0; i < n * n; ++i) {
      mean_a += first.channels[c][i];
      mean_b += second.channels[c][i];
    }
    mean_a /= double(n * n);
    mean_b /= double(n * n);
    for (size_t y = 0; y < n; ++y) {
      for (size_t x = 0; x < n; ++x) {
        const double w = hann(x) * hann(y);
        a[y * n + x] = (first.channels[c][y * n + x] - mean_a) * w;
        b[y * n + x] = (second.channels[c][y * n + x] - mean_b) * w;
      }
    }
    fft2(a, n, false);
    fft2(b, n, false);
    for (size_t i = 0; i < n * n; ++i) cross[i] += b[i] * std::conj(a[i]);
  }
  // Bins far weaker than the strongest hold only the window's leakage, whose phase says nothing
  // of the shift; normalised like the others they would bury the peak (and pull it towards 0).
  double largest = 0.0;
  for (const Complex& value : cross) largest = std::max(largest, std::abs(value));
  for (Complex& value : cross) {
    const double magnitude = std::abs(value);
    value = magnitude > kLeakageFloor * largest ? value / magnitude : Complex(0.0, 0.0);
  }
  fft2(cross, n, true);
  size_t best = 0;
  for (size_t i = 1; i < n * n; ++i) {
    if (cross[i].real() > cross[best].real()) best = i;
  }
  const auto at = [&](long x, long y) {
    return cross[((y + long(n)) % long(n)) * n + (x + long(n)) % long(n)].real();
  };
  const long bx = long(best % n), by = long(best / n);
  const auto refine = [](double left, double centre, double right) {
    const double curvature = left - 2.0 * centre + right;
    return curvature < 0.0 ? 0.5 * (left - right) / curvature : 0.0;
  };
  const double c0 = at(bx, by);
  glm::dvec2 shift(double(bx) + refine(at(bx - 1, by), c0, at(bx + 1, by)),
                   double(by) + refine(at(bx, by - 1), c0, at(bx, by + 1)));
  if (shift.x > double(n) / 2) shift.x -= double(n);
  if (shift.y > double(n) / 2) shift.y -= double(n);
  if (peak != nullptr) *peak = c0 / double(n * n);
  return shift;
}

}  // namespace siviflow::testing
