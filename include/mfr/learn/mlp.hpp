// The deep k-buffer's importance predictor (Tsopouridis, Vasilakis, Fudos, "Deep hybrid
// order-independent transparency", sec. 3.1.3, Fig. 4): a fully connected network
// 12 -> 128 -> 64 -> 1, ReLU on the hidden layers, sigmoid on the output, trained with mean squared
// error and plain mini-batch SGD (learning rate 1e-3, batch 512), L1 regularisation on the first
// and L2 on the second hidden layer's weights.
//
// Samples are columns: a batch is a (inputs x count) column-major matrix. Eigen does the algebra.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mfr/core/isa.hpp"
#include "mfr/core/result.hpp"

namespace mfr::learn {

/// Layer sizes of the paper's network.
inline const std::vector<int> kDkbLayers = {12, 128, 64, 1};

struct Mlp {
  std::vector<int> sizes;                // input, hidden..., output
  std::vector<Eigen::MatrixXf> weights;  // layer l: sizes[l + 1] x sizes[l]
  std::vector<Eigen::VectorXf> biases;   // layer l: sizes[l + 1]
  int inputs() const { return sizes.front(); }
  int outputs() const { return sizes.back(); }
  size_t parameterCount() const;
};

/// Programmer check (MFR_CHECK): the matrices agree with `sizes`.
void checkShapes(const Mlp& net);

/// He-uniform weights, zero biases, deterministic from the seed.
Mlp makeMlp(const std::vector<int>& sizes, uint64_t seed);

/// Forward pass of a batch: `inputs` is (sizes[0] x count); returns (sizes.back() x count). On
/// the instruction set of activeIsa(): the AVX2 / AVX-512 kernels, or Eigen on the scalar path
/// (they agree within float rounding; each is deterministic for any batch and thread count).
Eigen::MatrixXf predict(const Mlp& net, const Eigen::MatrixXf& inputs);

/// The same on a given path (lowered to what the CPU has): for tests comparing the paths.
Eigen::MatrixXf predict(const Mlp& net, const Eigen::MatrixXf& inputs, Isa isa);

/// Inference over `count` samples stored row by row (count x inputs floats, sample-major, as the
/// feature pass writes them) into `out` (count x outputs), in fixed-size chunks on oneTBB workers:
/// the result does not depend on the number of threads.
void predictRows(const Mlp& net, const float* rows, size_t count, float* out);

struct Regularization {
  float l1FirstHidden = 1e-5f;   // lambda_1 * sum |W_1| (weights into the first hidden layer)
  float l2SecondHidden = 1e-4f;  // lambda_2 * sum W_2^2 (weights into the second hidden layer)
};

/// Gradients with the shapes of the network's parameters.
struct Gradients {
  std::vector<Eigen::MatrixXf> weights;
  std::vector<Eigen::VectorXf> biases;
};

/// Loss of a batch, loss = mean over samples and outputs of (y - t)^2 + regularisation, and its
/// gradient. `inputs` (sizes[0] x count), `targets` (outputs x count). Returns the total loss.
double lossAndGradients(const Mlp& net, const Eigen::MatrixXf& inputs,
                        const Eigen::MatrixXf& targets, const Regularization& reg,
                        Gradients& grads);

/// Mean squared error alone (no regularisation) over a data set, batched.
double meanSquaredError(const Mlp& net, const Eigen::MatrixXf& inputs,
                        const Eigen::MatrixXf& targets);

struct TrainOptions {
  int epochs = 20;
  int batchSize = 512;
  float learningRate = 1e-3f;
  float momentum = 0.0f;  // 0: the paper's plain SGD
  Regularization regularization;
  uint64_t seed = 1;  // shuffling order
};

struct EpochLog {
  int epoch = 0;                // 1-based
  double trainLoss = 0.0;       // mean squared error on the training set after the epoch
  double validationLoss = 0.0;  // mean squared error on the validation set (NaN if empty)
  double seconds = 0.0;
};

/// Trains in place, single-threaded and deterministic from the options' seed (shuffle per epoch
/// with a seeded generator). Calls `onEpoch` after every epoch.
std::vector<EpochLog> train(Mlp& net, const Eigen::MatrixXf& trainInputs,
                            const Eigen::MatrixXf& trainTargets,
                            const Eigen::MatrixXf& validationInputs,
                            const Eigen::MatrixXf& validationTargets, const TrainOptions& options,
                            const std::function<void(const EpochLog&)>& onEpoch = {});

}  // namespace mfr::learn
