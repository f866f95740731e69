#include "analysis/pca.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace solidtex {

PcaProjection PcaProjection::of(const PcaBasis& b) {
  PcaProjection p;
  p.input_dims = b.input_dims;
  p.output_dims = b.output_dims;
  p.stride = (b.output_dims + 7) / 8 * 8;
  p.mean = b.mean;
  p.basis_t.assign(size_t(b.input_dims) * p.stride, 0.f);
  for (int r = 0; r < b.output_dims; ++r)
    for (int i = 0; i < b.input_dims; ++i) p.basis_t[size_t(i) * p.stride + r] = b.basis[size_t(r) * b.input_dims + i];
  return p;
}

namespace {
// out[r] = sum over i ascending of row_i[r] * (in[i] - mean[i]), accumulated from +0 without
// FMA, so the AVX2 and baseline clones give the same bits.
template <int S>
[[gnu::always_inline]] inline void project_block(const PcaProjection& p, const float* in, float* out) {
  float acc[S] = {};
  const float* row = p.basis_t.data();
  for (int i = 0; i < p.input_dims; ++i, row += S) {
    const float centred = in[i] - p.mean[size_t(i)];
    for (int r = 0; r < S; ++r) acc[r] += row[r] * centred;
  }
  for (int r = 0; r < p.output_dims; ++r) out[r] = acc[r];
}
}  // namespace

__attribute__((target_clones("avx2", "default"))) void PcaProjection::project(const float* in, float* out) const {
  switch (stride) {
    case 8: return project_block<8>(*this, in, out);
    case 16: return project_block<16>(*this, in, out);
    case 24: return project_block<24>(*this, in, out);
    case 32: return project_block<32>(*this, in, out);
    case 40: return project_block<40>(*this, in, out);
    case 48: return project_block<48>(*this, in, out);
    case 56: return project_block<56>(*this, in, out);
    case 64: return project_block<64>(*this, in, out);
    default: break;
  }
  for (int r = 0; r < output_dims; ++r) out[r] = 0.f;  // wider than any analysis makes
  for (int i = 0; i < input_dims; ++i) {
    const float centred = in[i] - mean[size_t(i)];
    const float* row = basis_t.data() + size_t(i) * stride;
    for (int r = 0; r < output_dims; ++r) out[r] += row[r] * centred;
  }
}

Result<PcaBasis> fit_pca(const std::vector<float>& samples, int count, int dims, int output_dims) {
  if (count < 2 || dims < 1 || samples.size() != size_t(count) * dims)
    return Status(StatusCode::kInvalidArgument, "PCA needs at least two samples of matching size");
  output_dims = std::clamp(output_dims, 1, dims);
  Eigen::Map<const Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> x(samples.data(), count, dims);
  Eigen::VectorXd mean = x.cast<double>().colwise().mean().transpose();
  Eigen::MatrixXd centred = x.cast<double>().rowwise() - mean.transpose();
  Eigen::MatrixXd cov = (centred.transpose() * centred) / double(count - 1);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(cov);
  if (eig.info() != Eigen::Success) return Status(StatusCode::kInternal, "PCA eigen-decomposition failed");

  PcaBasis b;
  b.input_dims = dims;
  b.output_dims = output_dims;
  b.mean.resize(dims);
  for (int i = 0; i < dims; ++i) b.mean[i] = float(mean[i]);
  b.basis.resize(size_t(output_dims) * dims);
  for (int r = 0; r < output_dims; ++r) {
    Eigen::VectorXd v = eig.eigenvectors().col(dims - 1 - r);  // ascending eigenvalues
    Eigen::Index arg = 0;
    v.cwiseAbs().maxCoeff(&arg);
    if (v[arg] < 0) v = -v;
    for (int i = 0; i < dims; ++i) b.basis[size_t(r) * dims + i] = float(v[i]);
  }
  return b;
}

}  // namespace solidtex
