#include "analysis/pca.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace solidtex {

void PcaBasis::project(const float* in, float* out) const {
  // Centre once, then one dot product per output in a fixed order.
  float centred[1024];
  std::vector<float> heap;
  float* c = centred;
  if (input_dims > 1024) {
    heap.resize(input_dims);
    c = heap.data();
  }
  for (int i = 0; i < input_dims; ++i) c[i] = in[i] - mean[i];
  for (int r = 0; r < output_dims; ++r) {
    const float* b = &basis[size_t(r) * input_dims];
    float s = 0.f;
    for (int i = 0; i < input_dims; ++i) s += b[i] * c[i];
    out[r] = s;
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
