// The importance MLP (mfr/learn/mlp.hpp) and its model file (mfr/learn/model_file.hpp) against
// independent expectations: a forward pass worked out by hand, gradients against central finite
// differences of a double-precision reference written here, training on a synthetic task,
// determinism (seeds, thread counts, pointer alignment), the byte layout of the file as the header
// specifies it, bit-exact round trips and the rejection of damaged files.
#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

#include "mfr/learn/mlp.hpp"
#include "mfr/learn/model_file.hpp"

namespace mfr::learn {
namespace {

// --- helpers ------------------------------------------------------------------------------------

/// Uniform double in [lo, hi) from a raw generator output (the test's own draw).
double uniform(std::mt19937_64& gen, double lo, double hi) {
  return lo + (hi - lo) * (static_cast<double>(gen() >> 11) * 0x1.0p-53);
}

Eigen::MatrixXf randomMatrix(Eigen::Index rows, Eigen::Index cols, std::mt19937_64& gen, double lo,
                             double hi) {
  Eigen::MatrixXf m(rows, cols);
  for (Eigen::Index c = 0; c < cols; ++c) {
    for (Eigen::Index r = 0; r < rows; ++r) m(r, c) = static_cast<float>(uniform(gen, lo, hi));
  }
  return m;
}

template <typename A, typename B>
bool bitwiseEqual(const A& a, const B& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(float) * static_cast<size_t>(a.size())) == 0;
}

bool sameParameters(const Mlp& a, const Mlp& b) {
  if (a.sizes != b.sizes || a.weights.size() != b.weights.size()) return false;
  for (size_t l = 0; l < a.weights.size(); ++l) {
    if (!bitwiseEqual(a.weights[l], b.weights[l]) || !bitwiseEqual(a.biases[l], b.biases[l])) {
      return false;
    }
  }
  return true;
}

bool allParametersFinite(const Mlp& net) {
  for (size_t l = 0; l < net.weights.size(); ++l) {
    if (!net.weights[l].allFinite() || !net.biases[l].allFinite()) return false;
  }
  return true;
}

/// Gives every bias a random value (makeMlp's are zero) so that tests exercise them.
void randomizeBiases(Mlp& net, std::mt19937_64& gen, double scale) {
  for (Eigen::VectorXf& b : net.biases) b = randomMatrix(b.size(), 1, gen, -scale, scale);
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// --- initialisation -----------------------------------------------------------------------------

TEST(Mlp, ParameterCountShapesAndHeUniformInit) {
  const Mlp net = makeMlp(kDkbLayers, 42);
  // 12*128 + 128 + 128*64 + 64 + 64*1 + 1
  EXPECT_EQ(net.parameterCount(), 1536u + 128u + 8192u + 64u + 64u + 1u);
  EXPECT_EQ(net.inputs(), 12);
  EXPECT_EQ(net.outputs(), 1);
  ASSERT_EQ(net.weights.size(), 3u);
  ASSERT_EQ(net.biases.size(), 3u);
  const int rows[3] = {128, 64, 1}, cols[3] = {12, 128, 64};
  for (size_t l = 0; l < 3; ++l) {
    EXPECT_EQ(net.weights[l].rows(), rows[l]);
    EXPECT_EQ(net.weights[l].cols(), cols[l]);
    EXPECT_EQ(net.biases[l].size(), rows[l]);
    EXPECT_TRUE((net.biases[l].array() == 0.0f).all()) << "layer " << l;
    const double limit = std::sqrt(6.0 / cols[l]);
    EXPECT_LE(net.weights[l].cwiseAbs().maxCoeff(), limit) << "layer " << l;
  }
  // U(-a, a) has mean 0 and variance a^2 / 3; layer 1 has 8192 weights, a^2 = 6 / 128
  const Eigen::ArrayXd w = net.weights[1].cast<double>().reshaped().array();
  const double mean = w.mean(), variance = (w - mean).square().mean();
  const double expectedVariance = 6.0 / 128.0 / 3.0;
  EXPECT_LT(std::abs(mean), 4.0 * std::sqrt(expectedVariance / 8192.0));
  EXPECT_NEAR(variance, expectedVariance, 0.05 * expectedVariance);

  EXPECT_TRUE(sameParameters(net, makeMlp(kDkbLayers, 42)));
  EXPECT_FALSE(sameParameters(net, makeMlp(kDkbLayers, 43)));
}

// --- forward pass -------------------------------------------------------------------------------

/// 2 -> 3 -> 2 -> 1 with hand-chosen parameters.
Mlp handSetNet() {
  Mlp net;
  net.sizes = {2, 3, 2, 1};
  Eigen::MatrixXf w0(3, 2), w1(2, 3), w2(1, 2);
  w0 << 0.5f, -1.0f,  //
      1.5f, 0.25f,    //
      -0.5f, -0.5f;
  w1 << 1.0f, -0.5f, 2.0f,  //
      0.25f, 0.5f, -1.0f;
  w2 << 0.75f, -1.5f;
  Eigen::VectorXf b0(3), b1(2), b2(1);
  b0 << 0.1f, -0.2f, 0.3f;
  b1 << 0.5f, -0.25f;
  b2 << 0.2f;
  net.weights = {w0, w1, w2};
  net.biases = {b0, b1, b2};
  return net;
}

TEST(Mlp, ForwardPassMatchesHandArithmetic) {
  const Mlp net = handSetNet();
  Eigen::MatrixXf x(2, 3);
  x << 2.0f, -1.0f, 0.0f,  //
      1.0f, 3.0f, 0.0f;
  const auto sigmoid = [](double z) { return 1.0 / (1.0 + std::exp(-z)); };
  // sample (2, 1):
  //   z0 = (0.5*2 - 1*1 + 0.1, 1.5*2 + 0.25*1 - 0.2, -0.5*2 - 0.5*1 + 0.3) = (0.1, 3.05, -1.2)
  //   h1 = (0.1, 3.05, 0)
  //   z1 = (1*0.1 - 0.5*3.05 + 2*0 + 0.5, 0.25*0.1 + 0.5*3.05 - 1*0 - 0.25) = (-0.925, 1.3)
  //   h2 = (0, 1.3);  z2 = 0.75*0 - 1.5*1.3 + 0.2 = -1.75
  // sample (-1, 3):
  //   z0 = (-0.5 - 3 + 0.1, -1.5 + 0.75 - 0.2, 0.5 - 1.5 + 0.3) = (-3.4, -0.95, -0.7): h1 = 0
  //   z1 = b1 = (0.5, -0.25);  h2 = (0.5, 0);  z2 = 0.75*0.5 + 0.2 = 0.575
  // sample (0, 0):
  //   z0 = b0 = (0.1, -0.2, 0.3);  h1 = (0.1, 0, 0.3)
  //   z1 = (0.1 + 2*0.3 + 0.5, 0.25*0.1 - 1*0.3 - 0.25) = (1.2, -0.525);  h2 = (1.2, 0)
  //   z2 = 0.75*1.2 + 0.2 = 1.1
  const double expected[3] = {sigmoid(-1.75), sigmoid(0.575), sigmoid(1.1)};

  const Eigen::MatrixXf y = predict(net, x);
  ASSERT_EQ(y.rows(), 1);
  ASSERT_EQ(y.cols(), 3);
  float rowsOut[3] = {};
  predictRows(net, x.data(), 3, rowsOut);  // a column-major (2 x 3) matrix is 3 rows of 2
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(y(0, i), expected[i], 1e-6) << "sample " << i;
    EXPECT_NEAR(rowsOut[i], expected[i], 1e-6) << "sample " << i;
  }
}

// --- loss and gradients -------------------------------------------------------------------------

/// The network in double precision, written independently of the library: w[l][r * in + c].
struct RefNet {
  std::vector<int> sizes;
  std::vector<std::vector<double>> w, b;
};

RefNet toRef(const Mlp& net) {
  RefNet ref;
  ref.sizes = net.sizes;
  for (size_t l = 0; l < net.weights.size(); ++l) {
    std::vector<double> w, b;
    for (int r = 0; r < net.sizes[l + 1]; ++r) {
      for (int c = 0; c < net.sizes[l]; ++c) w.push_back(net.weights[l](r, c));
      b.push_back(net.biases[l](r));
    }
    ref.w.push_back(w);
    ref.b.push_back(b);
  }
  return ref;
}

/// Forward pass of one sample; `minAbsHidden` collects the smallest |pre-activation| of a hidden
/// unit (how close the sample is to a ReLU kink).
std::vector<double> refForward(const RefNet& n, std::vector<double> a, double& minAbsHidden) {
  const size_t layers = n.w.size();
  for (size_t l = 0; l < layers; ++l) {
    const int in = n.sizes[l], out = n.sizes[l + 1];
    std::vector<double> next(static_cast<size_t>(out));
    for (int r = 0; r < out; ++r) {
      double z = n.b[l][static_cast<size_t>(r)];
      for (int c = 0; c < in; ++c) {
        z += n.w[l][static_cast<size_t>(r * in + c)] * a[static_cast<size_t>(c)];
      }
      if (l + 1 < layers) {
        minAbsHidden = std::min(minAbsHidden, std::abs(z));
        next[static_cast<size_t>(r)] = std::max(z, 0.0);
      } else {
        next[static_cast<size_t>(r)] = 1.0 / (1.0 + std::exp(-z));
      }
    }
    a = next;
  }
  return a;
}

/// mean over outputs x samples of (y - t)^2 + l1 sum |W_0| + l2 sum W_1^2.
double refLoss(const RefNet& n, const Eigen::MatrixXf& x, const Eigen::MatrixXf& t, double l1,
               double l2, double& minAbsHidden) {
  double sum = 0.0;
  for (Eigen::Index j = 0; j < x.cols(); ++j) {
    std::vector<double> a(static_cast<size_t>(x.rows()));
    for (Eigen::Index i = 0; i < x.rows(); ++i) a[static_cast<size_t>(i)] = x(i, j);
    const std::vector<double> y = refForward(n, a, minAbsHidden);
    for (size_t o = 0; o < y.size(); ++o) {
      const double d = y[o] - t(static_cast<Eigen::Index>(o), j);
      sum += d * d;
    }
  }
  double reg = 0.0;
  for (double w : n.w[0]) reg += l1 * std::abs(w);
  for (double w : n.w[1]) reg += l2 * w * w;
  return sum / static_cast<double>(t.size()) + reg;
}

TEST(Mlp, GradientsMatchCentralDifferencesOfADoubleReference) {
  std::mt19937_64 gen(2024);
  Mlp net = makeMlp({4, 5, 3, 2}, 11);
  randomizeBiases(net, gen, 0.3);
  const Eigen::MatrixXf x = randomMatrix(4, 16, gen, -2.0, 2.0);
  const Eigen::MatrixXf t = randomMatrix(2, 16, gen, 0.0, 1.0);
  Regularization reg;
  reg.l1FirstHidden = 0.01f;
  reg.l2SecondHidden = 0.02f;
  const double l1 = reg.l1FirstHidden, l2 = reg.l2SecondHidden;

  Gradients grads;
  const double loss = lossAndGradients(net, x, t, reg, grads);
  RefNet ref = toRef(net);
  double minAbsHidden = std::numeric_limits<double>::infinity();
  EXPECT_NEAR(loss, refLoss(ref, x, t, l1, l2, minAbsHidden), 1e-6 * loss);
  // central differences are only meaningful away from the kinks of ReLU and |w|
  const double h = 1e-5;
  ASSERT_GT(minAbsHidden, 1e-3);
  for (double w : ref.w[0]) ASSERT_GT(std::abs(w), 1e-3);

  ASSERT_EQ(grads.weights.size(), 3u);
  ASSERT_EQ(grads.biases.size(), 3u);
  int checked = 0;
  const auto check = [&](double& parameter, float analytic, const std::string& what) {
    const double saved = parameter;
    double ignored = 0.0;
    parameter = saved + h;
    const double up = refLoss(ref, x, t, l1, l2, ignored);
    parameter = saved - h;
    const double down = refLoss(ref, x, t, l1, l2, ignored);
    parameter = saved;
    const double numeric = (up - down) / (2.0 * h);
    EXPECT_NEAR(analytic, numeric, 1e-3 * std::abs(numeric) + 1e-6) << what;
    ++checked;
  };
  for (size_t l = 0; l < 3; ++l) {
    const int in = net.sizes[l], out = net.sizes[l + 1];
    ASSERT_EQ(grads.weights[l].rows(), out);
    ASSERT_EQ(grads.weights[l].cols(), in);
    ASSERT_EQ(grads.biases[l].size(), out);
    for (int r = 0; r < out; ++r) {
      for (int c = 0; c < in; ++c) {
        std::string what = "weight l";
        what += std::to_string(l);
        what += " r";
        what += std::to_string(r);
        what += " c";
        what += std::to_string(c);
        check(ref.w[l][static_cast<size_t>(r * in + c)], grads.weights[l](r, c), what);
      }
      std::string what = "bias l";
      what += std::to_string(l);
      what += " r";
      what += std::to_string(r);
      check(ref.b[l][static_cast<size_t>(r)], grads.biases[l](r), what);
    }
  }
  EXPECT_EQ(checked, static_cast<int>(net.parameterCount()));
}

TEST(Mlp, RegularisationHitsOnlyTheFirstTwoHiddenLayers) {
  std::mt19937_64 gen(5);
  Mlp net = makeMlp({4, 5, 3, 1}, 3);
  randomizeBiases(net, gen, 0.2);
  net.weights[0](0, 0) = 0.0f;  // sign(0) = 0: no L1 push on an exact zero
  const Eigen::MatrixXf x = randomMatrix(4, 8, gen, -1.0, 1.0);
  const Eigen::MatrixXf t = randomMatrix(1, 8, gen, 0.0, 1.0);
  Regularization none, reg;
  none.l1FirstHidden = none.l2SecondHidden = 0.0f;
  reg.l1FirstHidden = 0.01f;
  reg.l2SecondHidden = 0.03f;
  Gradients g0, g1;
  const double loss0 = lossAndGradients(net, x, t, none, g0);
  const double loss1 = lossAndGradients(net, x, t, reg, g1);

  const Eigen::MatrixXd w0 = net.weights[0].cast<double>(), w1 = net.weights[1].cast<double>();
  const double l1 = reg.l1FirstHidden, l2 = reg.l2SecondHidden;  // the float values, widened
  const double expectedPenalty = l1 * w0.cwiseAbs().sum() + l2 * w1.squaredNorm();
  EXPECT_NEAR(loss1 - loss0, expectedPenalty, 1e-9 * expectedPenalty);
  for (Eigen::Index i = 0; i < w0.size(); ++i) {
    const double sign = w0(i) > 0 ? 1.0 : (w0(i) < 0 ? -1.0 : 0.0);
    EXPECT_NEAR(g1.weights[0](i) - g0.weights[0](i), l1 * sign, 1e-7) << "W0 entry " << i;
  }
  EXPECT_EQ(g1.weights[0](0, 0), g0.weights[0](0, 0));
  for (Eigen::Index i = 0; i < w1.size(); ++i) {
    EXPECT_NEAR(g1.weights[1](i) - g0.weights[1](i), 2.0 * l2 * w1(i), 1e-7) << "W1 entry " << i;
  }
  EXPECT_TRUE(bitwiseEqual(g1.weights[2], g0.weights[2]));  // output layer: no penalty
  for (size_t l = 0; l < 3; ++l) EXPECT_TRUE(bitwiseEqual(g1.biases[l], g0.biases[l]));

  // one hidden layer: weights[1] is the output layer, which has no L2
  const Mlp shallow = makeMlp({4, 5, 1}, 3);
  Gradients s0, s1;
  const double shallow0 = lossAndGradients(shallow, x, t, none, s0);
  const double shallow1 = lossAndGradients(shallow, x, t, reg, s1);
  const double l1Only = l1 * shallow.weights[0].cast<double>().cwiseAbs().sum();
  EXPECT_NEAR(shallow1 - shallow0, l1Only, 1e-9 * l1Only);
  EXPECT_TRUE(bitwiseEqual(s1.weights[1], s0.weights[1]));
}

// --- training -----------------------------------------------------------------------------------

struct Dataset {
  Eigen::MatrixXf inputs, targets;
};

/// target = sigmoid(a . x + 0.1), x uniform in [-1, 1]^12.
Dataset syntheticDataset(int count, uint64_t seed) {
  static const double a[12] = {1.5, -2.0, 0.5, 1.0, -1.0, 0.25, 2.0, -0.75, 0.6, -1.2, 0.9, -0.3};
  std::mt19937_64 gen(seed);
  Dataset d{randomMatrix(12, count, gen, -1.0, 1.0), Eigen::MatrixXf(1, count)};
  for (int j = 0; j < count; ++j) {
    double z = 0.1;
    for (int i = 0; i < 12; ++i) z += a[i] * d.inputs(i, j);
    d.targets(0, j) = static_cast<float>(1.0 / (1.0 + std::exp(-z)));
  }
  return d;
}

/// Mean squared error by hand from predict, on the scalar path: training and its losses use
/// Eigen's forward pass whatever the inference path (the wide kernels differ by float rounding).
double referenceMse(const Mlp& net, const Dataset& d) {
  const Eigen::MatrixXd diff = (predict(net, d.inputs, Isa::Scalar) - d.targets).cast<double>();
  return diff.squaredNorm() / static_cast<double>(diff.size());
}

TEST(MlpTraining, CutsTheValidationLossTenfoldOnASyntheticTask) {
  const Dataset trainSet = syntheticDataset(2000, 1), validation = syntheticDataset(500, 2);
  Mlp net = makeMlp(kDkbLayers, 7);
  const double initial = meanSquaredError(net, validation.inputs, validation.targets);
  EXPECT_NEAR(initial, referenceMse(net, validation), 1e-9);
  TrainOptions options;
  options.epochs = 5;
  options.batchSize = 32;  // 2000 = 62 * 32 + 16: a partial last batch
  options.learningRate = 0.05f;
  options.seed = 3;
  std::vector<EpochLog> reported;
  const std::vector<EpochLog> logs =
      train(net, trainSet.inputs, trainSet.targets, validation.inputs, validation.targets, options,
            [&](const EpochLog& log) { reported.push_back(log); });
  ASSERT_EQ(logs.size(), 5u);
  ASSERT_EQ(reported.size(), 5u);
  for (size_t e = 0; e < logs.size(); ++e) {
    EXPECT_EQ(logs[e].epoch, static_cast<int>(e) + 1);
    EXPECT_EQ(reported[e].validationLoss, logs[e].validationLoss);
    EXPECT_GE(logs[e].seconds, 0.0);
  }
  EXPECT_NEAR(logs.back().validationLoss, referenceMse(net, validation), 1e-9);
  EXPECT_NEAR(logs.back().trainLoss, referenceMse(net, trainSet), 1e-9);
  EXPECT_LT(logs.back().validationLoss, 0.1 * initial)
      << "initial " << initial << ", after 5 epochs " << logs.back().validationLoss;
}

TEST(MlpTraining, IsBitForBitDeterministicFromTheSeed) {
  const Dataset trainSet = syntheticDataset(2000, 1), validation = syntheticDataset(300, 2);
  TrainOptions options;
  options.epochs = 3;
  options.batchSize = 64;  // 2000 = 31 * 64 + 16
  options.learningRate = 0.01f;
  options.momentum = 0.9f;
  const auto run = [&](uint64_t seed, std::vector<EpochLog>& logs) {
    Mlp net = makeMlp(kDkbLayers, 7);
    TrainOptions o = options;
    o.seed = seed;
    logs = train(net, trainSet.inputs, trainSet.targets, validation.inputs, validation.targets, o);
    return net;
  };
  std::vector<EpochLog> logsA, logsB, logsC;
  const Mlp a = run(5, logsA), b = run(5, logsB), c = run(6, logsC);
  EXPECT_TRUE(sameParameters(a, b));
  ASSERT_EQ(logsA.size(), 3u);
  ASSERT_EQ(logsB.size(), 3u);
  for (size_t e = 0; e < 3; ++e) {
    EXPECT_EQ(logsA[e].trainLoss, logsB[e].trainLoss);
    EXPECT_EQ(logsA[e].validationLoss, logsB[e].validationLoss);
  }
  EXPECT_FALSE(sameParameters(a, c));  // another shuffling order
  EXPECT_FALSE(sameParameters(a, makeMlp(kDkbLayers, 7)));
}

TEST(MlpTraining, StepsAreSgdWithMomentumOverAPartialBatch) {
  // one batch per epoch (512 > 100 samples: the partial last batch is the only one), so the
  // updates can be replayed by hand from lossAndGradients: v = m v - lr g, w += v
  const Dataset data = syntheticDataset(100, 4);
  Mlp start = makeMlp({12, 6, 4, 1}, 5);
  std::mt19937_64 gen(6);
  randomizeBiases(start, gen, 0.2);
  TrainOptions options;
  options.epochs = 2;
  options.batchSize = 512;
  options.learningRate = 0.5f;
  options.momentum = 0.5f;
  options.regularization.l1FirstHidden = 0.01f;
  options.regularization.l2SecondHidden = 0.01f;
  Mlp trained = start;
  const auto logs = train(trained, data.inputs, data.targets, data.inputs, data.targets, options);
  ASSERT_EQ(logs.size(), 2u);

  Mlp expected = start;
  Gradients v, g;
  for (int epoch = 0; epoch < 2; ++epoch) {
    (void)lossAndGradients(expected, data.inputs, data.targets, options.regularization, g);
    if (epoch == 0) v = g;  // shapes; the velocity starts at zero
    for (size_t l = 0; l < 3; ++l) {
      const float m = epoch == 0 ? 0.0f : options.momentum, lr = options.learningRate;
      v.weights[l] = m * v.weights[l] - lr * g.weights[l];
      v.biases[l] = m * v.biases[l] - lr * g.biases[l];
      expected.weights[l] += v.weights[l];
      expected.biases[l] += v.biases[l];
    }
  }
  // the shuffled column order changes float summation order only: compare with a tolerance
  for (size_t l = 0; l < 3; ++l) {
    EXPECT_LT((trained.weights[l] - expected.weights[l]).cwiseAbs().maxCoeff(), 1e-5f)
        << "layer " << l;
    EXPECT_LT((trained.biases[l] - expected.biases[l]).cwiseAbs().maxCoeff(), 1e-5f)
        << "layer " << l;
    EXPECT_GT((trained.weights[l] - start.weights[l]).cwiseAbs().maxCoeff(), 1e-3f)
        << "layer " << l << " did not move";
  }
}

TEST(MlpTraining, StopsBeforeANonFiniteUpdate) {
  Dataset trainSet = syntheticDataset(200, 1);
  const Dataset validation = syntheticDataset(50, 2);
  trainSet.targets(0, 7) = std::numeric_limits<float>::quiet_NaN();
  Mlp net = makeMlp({12, 16, 8, 1}, 1);
  TrainOptions options;
  options.epochs = 3;
  options.batchSize = 50;
  options.learningRate = 0.05f;
  int calls = 0;
  const std::vector<EpochLog> logs =
      train(net, trainSet.inputs, trainSet.targets, validation.inputs, validation.targets, options,
            [&](const EpochLog&) { ++calls; });
  // sample 7 is in some batch of the very first epoch: nothing completes
  EXPECT_TRUE(logs.empty());
  EXPECT_EQ(calls, 0);
  EXPECT_TRUE(allParametersFinite(net));

  // an empty validation set is allowed and reported as NaN
  Mlp other = makeMlp({12, 16, 8, 1}, 1);
  const Dataset clean = syntheticDataset(100, 1);
  const Eigen::MatrixXf noInputs(12, 0), noTargets(1, 0);
  const std::vector<EpochLog> logs2 =
      train(other, clean.inputs, clean.targets, noInputs, noTargets, options);
  ASSERT_EQ(logs2.size(), 3u);
  EXPECT_TRUE(std::isnan(logs2.back().validationLoss));
  EXPECT_TRUE(std::isfinite(logs2.back().trainLoss));
}

// --- inference over rows ------------------------------------------------------------------------

/// predictRows over sample-major rows copied from `x` (starting `offset` floats into a buffer, to
/// move the pointer off any alignment), with at most `threads` oneTBB threads (0: default).
std::vector<float> rowsPrediction(const Mlp& net, const Eigen::MatrixXf& x, size_t offset,
                                  int threads) {
  const size_t count = static_cast<size_t>(x.cols()), inputs = static_cast<size_t>(x.rows());
  std::vector<float> buffer(offset + count * inputs);
  for (size_t i = 0; i < count; ++i) {
    for (size_t k = 0; k < inputs; ++k) {
      buffer[offset + i * inputs + k] =
          x(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(i));
    }
  }
  std::vector<float> out(offset + count * static_cast<size_t>(net.outputs()), -1.0f);
  if (threads > 0) {
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                                    static_cast<size_t>(threads));
    predictRows(net, buffer.data() + offset, count, out.data() + offset);
  } else {
    predictRows(net, buffer.data() + offset, count, out.data() + offset);
  }
  return std::vector<float>(out.begin() + static_cast<std::ptrdiff_t>(offset), out.end());
}

TEST(MlpPredictRows, EqualsPredictForAnyThreadCountAndAlignment) {
  std::mt19937_64 gen(99);
  Mlp dkb = makeMlp(kDkbLayers, 8), small = makeMlp({5, 7, 3}, 9);
  randomizeBiases(dkb, gen, 0.5);
  randomizeBiases(small, gen, 0.5);
  const int count = 3 * 4096 + 123;  // three full chunks and a partial one
  for (const Mlp* net : {&dkb, &small}) {
    const Eigen::MatrixXf x = randomMatrix(net->inputs(), count, gen, -1.5, 1.5);
    const Eigen::MatrixXf y = predict(*net, x);
    ASSERT_EQ(y.rows(), net->outputs());
    ASSERT_EQ(y.cols(), count);
    for (int threads : {0, 1, 2}) {
      for (size_t offset : {size_t{0}, size_t{1}, size_t{3}}) {
        const std::vector<float> rows = rowsPrediction(*net, x, offset, threads);
        // out is (count x outputs) sample-major: the layout of the column-major (outputs x count)
        const Eigen::Map<const Eigen::MatrixXf> asColumns(rows.data(), net->outputs(), count);
        EXPECT_TRUE(bitwiseEqual(asColumns, y))
            << net->inputs() << " inputs, threads " << threads << ", offset " << offset;
      }
    }
  }
  // nothing to do is fine
  predictRows(dkb, nullptr, 0, nullptr);
  EXPECT_EQ(predict(dkb, Eigen::MatrixXf(12, 0)).cols(), 0);
}

// --- model file ---------------------------------------------------------------------------------

Model smallModel() {
  std::mt19937_64 gen(77);
  Model model{makeMlp({3, 4, 2}, 21), R"({"features":["depth","alpha"],"note":"é ü 深"})"};
  randomizeBiases(model.net, gen, 0.5);
  return model;
}

Model dkbModel() {
  std::mt19937_64 gen(78);
  Model model{makeMlp(kDkbLayers, 22), R"({"target":"importance","scale":[0,1]})"};
  randomizeBiases(model.net, gen, 0.5);
  return model;
}

uint32_t readU32(const std::vector<uint8_t>& b, size_t at) {
  return uint32_t{b[at]} | uint32_t{b[at + 1]} << 8 | uint32_t{b[at + 2]} << 16 |
         uint32_t{b[at + 3]} << 24;
}

void writeU32(std::vector<uint8_t>& b, size_t at, uint32_t v) {
  for (size_t i = 0; i < 4; ++i) b[at + i] = static_cast<uint8_t>(v >> (8 * i));
}

float readF32(const std::vector<uint8_t>& b, size_t at) {
  const uint32_t bits = readU32(b, at);
  float f;
  std::memcpy(&f, &bits, 4);
  return f;
}

void writeF32(std::vector<uint8_t>& b, size_t at, float f) {
  uint32_t bits;
  std::memcpy(&bits, &f, 4);
  writeU32(b, at, bits);
}

/// Offset of layer l's first weight in the file of a network with these sizes (from the header's
/// layout comment).
size_t layerOffset(const std::vector<int>& sizes, size_t l) {
  size_t at = 16 + 4 * sizes.size();
  for (size_t k = 0; k < l; ++k) at += 4 * static_cast<size_t>(sizes[k + 1] * (sizes[k] + 1));
  return at;
}

/// The error message of decoding `bytes`, or "" (and a failure) if it decodes.
std::string decodeError(const std::vector<uint8_t>& bytes, const std::string& name) {
  const auto model = decodeModel(bytes.data(), bytes.size(), name);
  if (model.ok()) {
    ADD_FAILURE() << name << " decoded without an error";
    return "";
  }
  return model.error().message;
}

std::string tempPath(const std::string& tag) {
  std::string path = ::testing::TempDir();
  path += "mfr_test_mlp_";
  path += std::to_string(::getpid());
  path += '_';
  path += tag;
  return path;
}

std::vector<uint8_t> fileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

TEST(ModelFile, LayoutMatchesTheHeaderComment) {
  const Model model = smallModel();
  const std::vector<uint8_t> bytes = encodeModel(model);
  const size_t m = model.metadata.size();
  // header 16, sizes 3 * 4, layer 0: (4*3 + 4) * 4, layer 1: (2*4 + 2) * 4, length 4, metadata
  ASSERT_EQ(bytes.size(), 16u + 12u + 64u + 40u + 4u + m);
  EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + 8), std::string("MFRMLP\0\0", 8));
  EXPECT_EQ(readU32(bytes, 8), 1u);
  EXPECT_EQ(readU32(bytes, 12), 2u);
  EXPECT_EQ(readU32(bytes, 16), 3u);
  EXPECT_EQ(readU32(bytes, 20), 4u);
  EXPECT_EQ(readU32(bytes, 24), 2u);
  // weights row-major (output row, then input), then the biases
  const Mlp& net = model.net;
  EXPECT_EQ(readF32(bytes, 28), net.weights[0](0, 0));
  EXPECT_EQ(readF32(bytes, 32), net.weights[0](0, 1));
  EXPECT_EQ(readF32(bytes, 40), net.weights[0](1, 0));
  EXPECT_EQ(readF32(bytes, 28 + 4 * 11), net.weights[0](3, 2));
  EXPECT_EQ(readF32(bytes, 28 + 4 * 12), net.biases[0](0));
  EXPECT_EQ(readF32(bytes, 92), net.weights[1](0, 0));
  EXPECT_EQ(readF32(bytes, 92 + 4 * 4), net.weights[1](1, 0));
  EXPECT_EQ(readF32(bytes, 92 + 4 * 9), net.biases[1](1));
  EXPECT_EQ(readU32(bytes, 132), m);
  EXPECT_EQ(std::string(bytes.begin() + 136, bytes.end()), model.metadata);
}

TEST(ModelFile, RoundTripsBitExactly) {
  for (Model model : {smallModel(), dkbModel()}) {
    // values whose bits a sloppy encoder would lose
    model.net.weights[0](0, 0) = -0.0f;
    model.net.weights[0](1, 0) = std::numeric_limits<float>::denorm_min();
    model.net.weights.back()(0, 0) = std::numeric_limits<float>::max();
    model.net.biases[0](1) = std::numeric_limits<float>::lowest();
    const std::vector<uint8_t> bytes = encodeModel(model);
    const auto decoded = decodeModel(bytes.data(), bytes.size(), "round trip");
    ASSERT_TRUE(decoded.ok()) << decoded.error().message;
    EXPECT_TRUE(sameParameters(decoded->net, model.net));
    EXPECT_EQ(decoded->metadata, model.metadata);
    EXPECT_EQ(encodeModel(decoded.value()), bytes);
    EXPECT_TRUE(std::signbit(decoded->net.weights[0](0, 0)));
  }
  // empty metadata is fine
  Model bare = smallModel();
  bare.metadata.clear();
  const std::vector<uint8_t> bytes = encodeModel(bare);
  const auto decoded = decodeModel(bytes.data(), bytes.size(), "bare");
  ASSERT_TRUE(decoded.ok()) << decoded.error().message;
  EXPECT_TRUE(decoded->metadata.empty());
}

TEST(ModelFile, RoundTripsThroughAFile) {
  const Model model = dkbModel();
  const std::string path = tempPath("roundtrip.mfrnn");
  const Result<void> written = writeModel(path, model);
  ASSERT_TRUE(written.ok()) << written.error().message;
  EXPECT_EQ(fileBytes(path), encodeModel(model));
  const auto read = readModel(path);
  ASSERT_TRUE(read.ok()) << read.error().message;
  EXPECT_TRUE(sameParameters(read->net, model.net));
  EXPECT_EQ(read->metadata, model.metadata);
  std::filesystem::remove(path);
}

TEST(ModelFile, RejectsWrongMagicAndOtherVersions) {
  const std::vector<uint8_t> good = encodeModel(smallModel());
  std::vector<uint8_t> bytes = good;
  bytes[3] = 'X';
  std::string message = decodeError(bytes, "magic.mfrnn");
  EXPECT_TRUE(contains(message, "magic.mfrnn") && contains(message, "magic")) << message;
  message = decodeError(std::vector<uint8_t>{'P', 'K', 3}, "zip.mfrnn");
  EXPECT_TRUE(contains(message, "zip.mfrnn") && contains(message, "magic")) << message;

  bytes = good;
  writeU32(bytes, 8, 2);
  message = decodeError(bytes, "v2.mfrnn");
  EXPECT_TRUE(contains(message, "v2.mfrnn") && contains(message, "version 2") &&
              contains(message, "version 1"))
      << message;
}

TEST(ModelFile, RejectsShapesOutOfRange) {
  const std::vector<uint8_t> good = encodeModel(smallModel());
  for (uint32_t layers : {0u, 17u, 0xFFFFFFFFu}) {
    std::vector<uint8_t> bytes = good;
    writeU32(bytes, 12, layers);
    const std::string message = decodeError(bytes, "layers.mfrnn");
    std::string expected = "layer count ";
    expected += std::to_string(layers);
    EXPECT_TRUE(contains(message, "layers.mfrnn") && contains(message, expected)) << message;
  }
  for (size_t slot = 0; slot < 3; ++slot) {
    for (uint32_t size : {0u, 4097u, 100000u}) {
      std::vector<uint8_t> bytes = good;
      writeU32(bytes, 16 + 4 * slot, size);
      const std::string message = decodeError(bytes, "sizes.mfrnn");
      std::string expected = "layer size ";
      expected += std::to_string(size);
      EXPECT_TRUE(contains(message, "sizes.mfrnn") && contains(message, expected)) << message;
    }
  }
}

TEST(ModelFile, RejectsTruncatedFilesAndTrailingBytes) {
  const Model model = dkbModel();
  const std::vector<uint8_t> good = encodeModel(model);
  const size_t size = good.size(), m = model.metadata.size();
  std::vector<size_t> cuts = {1,        7,       8,  11, 12,           15,           16,
                              17,       31,      32, 33, size - m - 5, size - m - 4, size - m - 1,
                              size - m, size - 1};
  for (size_t cut = 0; cut < size; cut += 1000) cuts.push_back(cut);
  for (size_t cut : cuts) {
    const std::vector<uint8_t> bytes(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(cut));
    const std::string message = decodeError(bytes, "cut.mfrnn");
    std::string got = "got ";
    got += std::to_string(cut);
    EXPECT_TRUE(contains(message, "cut.mfrnn") && contains(message, "truncated") &&
                contains(message, got))
        << "cut at " << cut << ": " << message;
  }
  std::vector<uint8_t> bytes = good;
  bytes.push_back(0);
  const std::string message = decodeError(bytes, "long.mfrnn");
  EXPECT_TRUE(contains(message, "long.mfrnn") && contains(message, "1 trailing byte")) << message;
}

TEST(ModelFile, RejectsNonFiniteParameters) {
  const Model model = smallModel();
  const std::vector<uint8_t> good = encodeModel(model);
  std::vector<uint8_t> bytes = good;
  writeF32(bytes, layerOffset(model.net.sizes, 1) + 4 * 5,  // layer 1, output 1, input 1
           std::numeric_limits<float>::quiet_NaN());
  std::string message = decodeError(bytes, "nan.mfrnn");
  EXPECT_TRUE(contains(message, "nan.mfrnn") && contains(message, "non-finite weight") &&
              contains(message, "layer 1"))
      << message;

  bytes = good;
  writeF32(bytes, layerOffset(model.net.sizes, 0) + 4 * (12 + 2),  // layer 0, bias 2
           std::numeric_limits<float>::infinity());
  message = decodeError(bytes, "inf.mfrnn");
  EXPECT_TRUE(contains(message, "inf.mfrnn") && contains(message, "non-finite bias") &&
              contains(message, "layer 0"))
      << message;

  // and writing one is refused
  Model bad = model;
  bad.net.weights[1](0, 0) = std::numeric_limits<float>::infinity();
  const std::string path = tempPath("bad.mfrnn");
  const Result<void> written = writeModel(path, bad);
  ASSERT_FALSE(written.ok());
  EXPECT_TRUE(contains(written.error().message, path) &&
              contains(written.error().message, "non-finite"))
      << written.error().message;
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(ModelFile, RejectsBadMetadata) {
  const Model model = smallModel();
  const std::vector<uint8_t> good = encodeModel(model);
  const size_t lengthAt = good.size() - model.metadata.size() - 4;
  std::vector<uint8_t> bytes = good;
  writeU32(bytes, lengthAt, (1u << 20) + 1);
  std::string message = decodeError(bytes, "meta.mfrnn");
  EXPECT_TRUE(contains(message, "meta.mfrnn") && contains(message, "metadata")) << message;

  bytes = good;
  bytes.back() = 0xC0;  // a lead byte with no continuation
  message = decodeError(bytes, "utf8.mfrnn");
  EXPECT_TRUE(contains(message, "utf8.mfrnn") && contains(message, "UTF-8")) << message;
}

TEST(ModelFile, ReportsUnreadableAndUnwritablePaths) {
  const std::string missing = tempPath("does_not_exist.mfrnn");
  auto read = readModel(missing);
  ASSERT_FALSE(read.ok());
  EXPECT_TRUE(contains(read.error().message, missing) &&
              contains(read.error().message, "no such file"))  // as scene files say it
      << read.error().message;

  read = readModel(::testing::TempDir());
  ASSERT_FALSE(read.ok());
  EXPECT_TRUE(contains(read.error().message, "directory")) << read.error().message;

  // a missing folder is made (every output does so); a file where the folder should be fails
  ASSERT_TRUE(writeModel(tempPath("new_folder/model.mfrnn"), smallModel()).ok());
  const std::string blocked = tempPath("new_folder/model.mfrnn/model.mfrnn");
  Result<void> written = writeModel(blocked, smallModel());
  ASSERT_FALSE(written.ok());
  EXPECT_TRUE(contains(written.error().message, blocked) &&
              contains(written.error().message, "cannot open"))
      << written.error().message;

  if (std::filesystem::exists("/dev/full")) {  // every write fails with ENOSPC
    written = writeModel("/dev/full", smallModel());
    ASSERT_FALSE(written.ok());
    EXPECT_TRUE(contains(written.error().message, "/dev/full") &&
                contains(written.error().message, "write error"))
        << written.error().message;
  }
}

}  // namespace
}  // namespace mfr::learn
