#include "analysis/pca.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace solidtex {

PcaProjection PcaProjection::of(const PcaBasis& b) {
  PcaProjection p;
  p.input_dims = b.input_dims;
  p.output_dims = b.output_dims;
  p.mean = b.mean;
  p.basis_t.resize(size_t(b.input_dims) * b.output_dims);
  for (int r = 0; r < b.output_dims; ++r)
    for (int i = 0; i < b.input_dims; ++i) p.basis_t[size_t(i) * b.output_dims + r] = b.basis[size_t(r) * b.input_dims + i];
  return p;
}

// Lane-wise identical whatever the vector width (no FMA, no reassociation), so the AVX2 and
// baseline clones give the same bits.
__attribute__((target_clones("avx2", "default"))) void PcaProjection::project(const float* in, float* out) const {
  const int d = output_dims;
  for (int r = 0; r < d; ++r) out[r] = 0.f;
  for (int i = 0; i < input_dims; ++i) {
    const float centred = in[i] - mean[size_t(i)];
    const float* row = basis_t.data() + size_t(i) * d;
    for (int r = 0; r < d; ++r) out[r] += row[r] * centred;  // independent accumulators: vectorises
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
