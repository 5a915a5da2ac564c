// The network's wide inference kernels (AVX2, AVX-512) against the scalar path (Eigen) and a
// double-precision reference: the same outputs within float rounding, and a sample's output does
// not depend on the batch around it. Paths the CPU lacks are skipped with a message.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mfr/core/isa.hpp"
#include "mfr/learn/mlp.hpp"

namespace mfr::learn {
namespace {

Eigen::MatrixXf uniformMatrix(Eigen::Index rows, Eigen::Index cols, std::mt19937_64& gen, float lo,
                              float hi) {
  std::uniform_real_distribution<float> u(lo, hi);
  Eigen::MatrixXf m(rows, cols);
  for (Eigen::Index c = 0; c < cols; ++c)
    for (Eigen::Index r = 0; r < rows; ++r) m(r, c) = u(gen);
  return m;
}

Mlp randomNet(const std::vector<int>& sizes, uint64_t seed) {
  Mlp net = makeMlp(sizes, seed);
  std::mt19937_64 gen(seed + 1);
  for (Eigen::VectorXf& b : net.biases) b = uniformMatrix(b.size(), 1, gen, -0.5f, 0.5f);
  return net;
}

/// The network in double precision, one sample at a time, written independently of the library.
double referenceOutput(const Mlp& net, const Eigen::MatrixXf& x, Eigen::Index sample, int o) {
  std::vector<double> a(static_cast<size_t>(x.rows()));
  for (Eigen::Index i = 0; i < x.rows(); ++i) a[static_cast<size_t>(i)] = x(i, sample);
  for (size_t l = 0; l < net.weights.size(); ++l) {
    const Eigen::MatrixXf& w = net.weights[l];
    std::vector<double> z(static_cast<size_t>(w.rows()));
    for (Eigen::Index r = 0; r < w.rows(); ++r) {
      double s = net.biases[l](r);
      for (Eigen::Index c = 0; c < w.cols(); ++c) s += double{w(r, c)} * a[static_cast<size_t>(c)];
      z[static_cast<size_t>(r)] =
          l + 1 < net.weights.size() ? std::max(s, 0.0) : 1.0 / (1.0 + std::exp(-s));
    }
    a = z;
  }
  return a[static_cast<size_t>(o)];
}

std::vector<Isa> widePaths() {
  std::vector<Isa> paths;
  for (Isa isa : {Isa::Avx2, Isa::Avx512})
    if (static_cast<int>(isa) <= static_cast<int>(detectedIsa())) paths.push_back(isa);
  return paths;
}

TEST(MlpKernels, WidePathsEqualTheScalarPathWithinFloatRounding) {
  if (widePaths().empty()) GTEST_SKIP() << "this CPU has neither AVX2 + FMA nor AVX-512";
  std::mt19937_64 gen(5);
  // the paper's network and shapes that fill no vector or register block evenly
  for (const std::vector<int>& sizes :
       std::vector<std::vector<int>>{kDkbLayers, {5, 7, 3}, {13, 1}, {3, 17, 9, 2}}) {
    const Mlp net = randomNet(sizes, 11 + sizes.size());
    for (Eigen::Index count : {1, 7, 33, 129, 300}) {
      const Eigen::MatrixXf x = uniformMatrix(net.inputs(), count, gen, -1.5f, 1.5f);
      const Eigen::MatrixXf scalar = predict(net, x, Isa::Scalar);
      for (Isa isa : widePaths()) {
        const Eigen::MatrixXf wide = predict(net, x, isa);
        ASSERT_EQ(wide.rows(), net.outputs());
        ASSERT_EQ(wide.cols(), count);
        for (Eigen::Index j = 0; j < count; ++j)
          for (int o = 0; o < net.outputs(); ++o) {
            const double ref = referenceOutput(net, x, j, o);
            // sigmoid outputs in (0, 1): float rounding of a 128-term sum is far below 1e-5
            EXPECT_NEAR(wide(o, j), scalar(o, j), 1e-5) << isaName(isa) << " sample " << j;
            EXPECT_NEAR(wide(o, j), ref, 1e-5) << isaName(isa) << " sample " << j;
          }
      }
    }
  }
}

TEST(MlpKernels, ASampleGivesTheSameBitsInAnyBatch) {
  if (widePaths().empty()) GTEST_SKIP() << "this CPU has neither AVX2 + FMA nor AVX-512";
  std::mt19937_64 gen(6);
  const Mlp net = randomNet(kDkbLayers, 3);
  const Eigen::MatrixXf x = uniformMatrix(net.inputs(), 200, gen, -1.0f, 1.0f);
  for (Isa isa : widePaths()) {
    const Eigen::MatrixXf all = predict(net, x, isa);
    for (Eigen::Index j : {0, 7, 8, 127, 128, 199}) {
      const Eigen::MatrixXf one = predict(net, x.middleCols(j, 1), isa);
      EXPECT_EQ(one(0, 0), all(0, j)) << isaName(isa) << " sample " << j;
    }
  }
}

TEST(MlpKernels, ActivePathFollowsSetActiveIsa) {
  // predict() without a path takes activeIsa(): forcing scalar gives Eigen's bits exactly
  std::mt19937_64 gen(7);
  const Mlp net = randomNet(kDkbLayers, 4);
  const Eigen::MatrixXf x = uniformMatrix(net.inputs(), 50, gen, -1.0f, 1.0f);
  const Isa before = activeIsa();
  setActiveIsa(Isa::Scalar);
  const Eigen::MatrixXf forced = predict(net, x);
  setActiveIsa(before);
  EXPECT_TRUE((forced.array() == predict(net, x, Isa::Scalar).array()).all());
  EXPECT_TRUE((predict(net, x).array() == predict(net, x, activeIsa()).array()).all());
}

}  // namespace
}  // namespace mfr::learn
