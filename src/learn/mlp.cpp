// The deep k-buffer's importance predictor: a small fully connected network (ReLU hidden layers,
// sigmoid output), its forward pass, its mean-squared-error loss with the paper's L1 / L2
// regularisation and the exact gradient, parallel inference over sample rows, and mini-batch SGD.
//
// Reference: A. Tsopouridis, A. A. Vasilakis, I. Fudos, "Deep hybrid order-independent
// transparency", sec. 3.1.3 and Fig. 4 (network 12 -> 128 -> 64 -> 1, MSE, SGD with learning rate
// 1e-3 and batch 512, L1 on the first and L2 on the second hidden layer's weights).
//
// Determinism and portability:
//  - makeMlp draws its He-uniform weights from std::mt19937_64's raw 64-bit outputs (the
//    generator's sequence is fixed by the standard; the distributions are not), converted here.
//  - train shuffles with Fisher-Yates and an unbiased integer drawn from the raw outputs by
//    rejection, so the sample order is the same with every standard library.
//  - predict and predictRows run one kernel on the same fixed chunks of kChunk samples (an Eigen
//    product's summation order may depend on the matrix sizes, never on the thread): they agree bit
//    for bit with each other and for any number of oneTBB threads. The kernel only reads the
//    caller's rows through Eigen's packing GEMM and keeps every elementwise operation on its own
//    (aligned) temporaries, so the alignment of the caller's pointers does not matter either.
//  - train is single-threaded; Eigen is built without OpenMP here, so its products are too.
//  - Inference (predict, predictRows) takes the path of activeIsa(): on AVX2 / AVX-512 the wide
//    kernels of learn/mlp_kernels.hpp (every sample summed in one fixed order, so a sample's
//    result is the same in any batch), on the scalar path Eigen's forward pass above. The two
//    agree within float rounding (fused multiply-adds, another summation order).
#include "mfr/learn/mlp.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "learn/mlp_kernels.hpp"

namespace mfr::learn {
namespace {

using Eigen::Index;

/// Samples per inference chunk: the unit of work of predictRows and the batching of predict and
/// meanSquaredError. Fixed, so that results never depend on the thread count.
constexpr Index kChunk = 4096;

/// Uniform double in [0, 1) from the top 53 bits of one raw generator output.
double uniform01(std::mt19937_64& gen) {
  return static_cast<double>(gen() >> 11) * 0x1.0p-53;
}

/// Uniform integer in [0, bound) from raw generator outputs, by rejection (unbiased): outputs below
/// 2^64 mod bound are redrawn, so the accepted range holds a whole number of copies of [0, bound).
uint64_t uniformBelow(std::mt19937_64& gen, uint64_t bound) {
  const uint64_t threshold = (uint64_t{0} - bound) % bound;  // 2^64 mod bound
  for (;;) {
    const uint64_t x = gen();
    if (x >= threshold) return x % bound;
  }
}

/// Fisher-Yates shuffle driven by uniformBelow.
void shuffle(std::vector<Index>& order, std::mt19937_64& gen) {
  for (size_t i = order.size(); i > 1; --i) {
    const size_t j = static_cast<size_t>(uniformBelow(gen, i));
    std::swap(order[i - 1], order[j]);
  }
}

void checkData(const Mlp& net, const Eigen::MatrixXf& inputs, const Eigen::MatrixXf& targets) {
  MFR_CHECK(inputs.rows() == net.inputs());
  MFR_CHECK(targets.rows() == net.outputs());
  MFR_CHECK(inputs.cols() == targets.cols());
}

bool isOutputLayer(const Mlp& net, size_t l) {
  return l + 1 == net.weights.size();
}

/// Pre-activation of layer l: W_l a + b_l.
Eigen::MatrixXf affine(const Mlp& net, size_t l, const Eigen::Ref<const Eigen::MatrixXf>& a) {
  Eigen::MatrixXf z = net.weights[l] * a;
  z.colwise() += net.biases[l];
  return z;
}

/// Layer l's activation in place: ReLU on hidden layers, sigmoid on the output layer.
void activate(const Mlp& net, size_t l, Eigen::MatrixXf& z) {
  if (isOutputLayer(net, l)) {
    z.array() = (1.0f + (-z.array()).exp()).inverse();
  } else {
    z.array() = z.array().max(0.0f);
  }
}

/// Output of the network for the columns of `x`.
Eigen::MatrixXf forward(const Mlp& net, const Eigen::Ref<const Eigen::MatrixXf>& x) {
  Eigen::MatrixXf a = affine(net, 0, x);
  activate(net, 0, a);
  for (size_t l = 1; l < net.weights.size(); ++l) {
    Eigen::MatrixXf z = affine(net, l, a);
    activate(net, l, z);
    a = std::move(z);
  }
  return a;
}

/// Samples per wide-kernel batch: the activations of a batch (widest layer x kWideBatch floats,
/// twice) stay in L2.
constexpr size_t kWideBatch = 128;

detail::DenseLayerKernel wideKernel(Isa isa) {
  switch (isa) {
    case Isa::Avx512:
      return detail::denseLayerAvx512();
    case Isa::Avx2:
      return detail::denseLayerAvx2();
    case Isa::Scalar:
      break;
  }
  return nullptr;
}

/// The network over `count` sample-major rows with a wide kernel: per batch of kWideBatch samples,
/// the rows transposed to the kernels' feature-major layout, the layers, then the sigmoid.
void forwardWide(const Mlp& net, detail::DenseLayerKernel dense, const float* rows, size_t count,
                 float* out) {
  const int inputs = net.inputs(), outputs = net.outputs();
  const int widest = *std::max_element(net.sizes.begin(), net.sizes.end());
  constexpr int stride = static_cast<int>(kWideBatch);
  static_assert(kWideBatch % detail::kBatchAlign == 0);
  // per-thread activations, reused across calls (a tile's batch is one call)
  thread_local std::vector<float> bufferA, bufferB;
  const size_t bufferSize = static_cast<size_t>(widest) * stride;
  if (bufferA.size() < bufferSize) {
    bufferA.resize(bufferSize);
    bufferB.resize(bufferSize);
  }
  float* a = bufferA.data();
  float* b = bufferB.data();
  const size_t layers = net.weights.size();
  for (size_t start = 0; start < count; start += kWideBatch) {
    const size_t n = std::min(kWideBatch, count - start);
    const float* x = rows + start * static_cast<size_t>(inputs);
    for (int i = 0; i < inputs; ++i) {
      float* dst = a + static_cast<size_t>(i) * stride;
      for (size_t j = 0; j < n; ++j) dst[j] = x[j * static_cast<size_t>(inputs) + i];
      std::fill(dst + n, dst + stride, 0.0f);  // padding: finite, ignored
    }
    for (size_t l = 0; l < layers; ++l) {
      dense(net.weights[l].data(), net.biases[l].data(), net.sizes[l + 1], net.sizes[l], a, b,
            stride, !isOutputLayer(net, l));
      std::swap(a, b);
    }
    float* y = out + start * static_cast<size_t>(outputs);
    for (int o = 0; o < outputs; ++o)
      for (size_t j = 0; j < n; ++j)
        y[j * static_cast<size_t>(outputs) + o] =
            1.0f / (1.0f + std::exp(-a[static_cast<size_t>(o) * stride + j]));
  }
}

/// Adds the regularisation's gradient to `grads` and returns its value. The first hidden layer is
/// weights[0] and exists when the network has a hidden layer; the second hidden layer is
/// weights[1] and exists when it has two. The output layer's weights are never regularised (with
/// one hidden layer, weights[1] is the output layer and gets no L2).
double addRegularization(const Mlp& net, const Regularization& reg, Gradients& grads) {
  const size_t hiddenLayers = net.weights.size() - 1;
  double loss = 0.0;
  if (hiddenLayers >= 1 && reg.l1FirstHidden != 0.0f) {
    const Eigen::MatrixXf& w = net.weights[0];
    loss += static_cast<double>(reg.l1FirstHidden) * w.cast<double>().cwiseAbs().sum();
    grads.weights[0].array() += reg.l1FirstHidden * w.array().sign();  // sign(0) = 0
  }
  if (hiddenLayers >= 2 && reg.l2SecondHidden != 0.0f) {
    const Eigen::MatrixXf& w = net.weights[1];
    loss += static_cast<double>(reg.l2SecondHidden) * w.cast<double>().squaredNorm();
    grads.weights[1] += (2.0f * reg.l2SecondHidden) * w;
  }
  return loss;
}

bool allFinite(const Gradients& grads) {
  for (size_t l = 0; l < grads.weights.size(); ++l) {
    if (!grads.weights[l].allFinite() || !grads.biases[l].allFinite()) return false;
  }
  return true;
}

Gradients zeroGradients(const Mlp& net) {
  Gradients g;
  for (size_t l = 0; l < net.weights.size(); ++l) {
    g.weights.push_back(Eigen::MatrixXf::Zero(net.weights[l].rows(), net.weights[l].cols()));
    g.biases.push_back(Eigen::VectorXf::Zero(net.biases[l].size()));
  }
  return g;
}

/// v = momentum v - lr g; w += v (plain SGD when momentum is 0: 0 v - lr g = -lr g exactly).
void sgdStep(Mlp& net, const Gradients& grads, Gradients& velocity, float lr, float momentum) {
  for (size_t l = 0; l < net.weights.size(); ++l) {
    velocity.weights[l] = momentum * velocity.weights[l] - lr * grads.weights[l];
    velocity.biases[l] = momentum * velocity.biases[l] - lr * grads.biases[l];
    net.weights[l] += velocity.weights[l];
    net.biases[l] += velocity.biases[l];
  }
}

/// Copies the columns order[start .. start + n) of `source` into `batch`.
void gather(const Eigen::MatrixXf& source, const std::vector<Index>& order, size_t start, Index n,
            Eigen::MatrixXf& batch) {
  batch.resize(source.rows(), n);
  for (Index j = 0; j < n; ++j) batch.col(j) = source.col(order[start + static_cast<size_t>(j)]);
}

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

void checkShapes(const Mlp& net) {
  MFR_CHECK(net.sizes.size() >= 2);
  MFR_CHECK(net.weights.size() + 1 == net.sizes.size());
  MFR_CHECK(net.biases.size() == net.weights.size());
  for (size_t l = 0; l < net.weights.size(); ++l) {
    MFR_CHECK(net.weights[l].rows() == net.sizes[l + 1] && net.weights[l].cols() == net.sizes[l]);
    MFR_CHECK(net.biases[l].size() == net.sizes[l + 1]);
  }
}

size_t Mlp::parameterCount() const {
  size_t count = 0;
  for (size_t l = 0; l + 1 < sizes.size(); ++l) {
    count += static_cast<size_t>(sizes[l]) * static_cast<size_t>(sizes[l + 1]);
    count += static_cast<size_t>(sizes[l + 1]);
  }
  return count;
}

Mlp makeMlp(const std::vector<int>& sizes, uint64_t seed) {
  MFR_CHECK(sizes.size() >= 2);
  for (int s : sizes) MFR_CHECK_GE(s, 1);
  std::mt19937_64 gen(seed);
  Mlp net;
  net.sizes = sizes;
  // layer by layer, each weight matrix row by row (output, then input): the file's order
  for (size_t l = 0; l + 1 < sizes.size(); ++l) {
    const double limit = std::sqrt(6.0 / sizes[l]);  // He uniform: U(-limit, limit)
    Eigen::MatrixXf w(sizes[l + 1], sizes[l]);
    for (Index r = 0; r < w.rows(); ++r) {
      for (Index c = 0; c < w.cols(); ++c) {
        w(r, c) = static_cast<float>((2.0 * uniform01(gen) - 1.0) * limit);
      }
    }
    net.weights.push_back(std::move(w));
    net.biases.push_back(Eigen::VectorXf::Zero(sizes[l + 1]));
  }
  return net;
}

Eigen::MatrixXf predict(const Mlp& net, const Eigen::MatrixXf& inputs) {
  return predict(net, inputs, activeIsa());
}

Eigen::MatrixXf predict(const Mlp& net, const Eigen::MatrixXf& inputs, Isa isa) {
  checkShapes(net);
  MFR_CHECK(inputs.rows() == net.inputs());
  Eigen::MatrixXf out(net.outputs(), inputs.cols());
  // never a path the CPU lacks
  if (static_cast<int>(isa) > static_cast<int>(detectedIsa())) isa = detectedIsa();
  const detail::DenseLayerKernel dense = wideKernel(isa);
  for (Index start = 0; start < inputs.cols(); start += kChunk) {
    const Index n = std::min(kChunk, inputs.cols() - start);
    if (dense) {
      forwardWide(net, dense, inputs.col(start).data(), static_cast<size_t>(n),
                  out.col(start).data());
    } else {
      out.middleCols(start, n) = forward(net, inputs.middleCols(start, n));
    }
  }
  return out;
}

void predictRows(const Mlp& net, const float* rows, size_t count, float* out) {
  checkShapes(net);
  const size_t chunk = static_cast<size_t>(kChunk);
  const size_t chunks = (count + chunk - 1) / chunk;
  const Index inputs = net.inputs(), outputs = net.outputs();
  const detail::DenseLayerKernel dense = wideKernel(activeIsa());
  tbb::parallel_for(size_t{0}, chunks, [&](size_t c) {
    const size_t start = c * chunk;
    const Index n = static_cast<Index>(std::min(chunk, count - start));
    if (dense) {
      forwardWide(net, dense, rows + start * static_cast<size_t>(inputs), static_cast<size_t>(n),
                  out + start * static_cast<size_t>(outputs));
      return;
    }
    // sample-major rows are the columns of a column-major (inputs x n) matrix
    const Eigen::Map<const Eigen::MatrixXf> x(rows + start * static_cast<size_t>(inputs), inputs,
                                              n);
    Eigen::Map<Eigen::MatrixXf>(out + start * static_cast<size_t>(outputs), outputs, n) =
        forward(net, x);
  });
}

double lossAndGradients(const Mlp& net, const Eigen::MatrixXf& inputs,
                        const Eigen::MatrixXf& targets, const Regularization& reg,
                        Gradients& grads) {
  checkShapes(net);
  checkData(net, inputs, targets);
  MFR_CHECK(inputs.cols() > 0);
  const size_t layers = net.weights.size();
  // forward, keeping each layer's activation
  std::vector<Eigen::MatrixXf> acts(layers);
  for (size_t l = 0; l < layers; ++l) {
    acts[l] = affine(net, l, l == 0 ? inputs : acts[l - 1]);
    activate(net, l, acts[l]);
  }
  const Eigen::MatrixXf& y = acts.back();
  const double n = static_cast<double>(targets.size());
  const Eigen::MatrixXf diff = y - targets;
  double loss = diff.cast<double>().squaredNorm() / n;

  // backward: delta = dLoss/dz of layer l, starting at the output, where
  // dLoss/dy = 2 (y - t) / n and the sigmoid's derivative is y (1 - y)
  Eigen::MatrixXf delta =
      (diff.array() * y.array() * (1.0f - y.array()) * static_cast<float>(2.0 / n)).matrix();
  grads.weights.resize(layers);
  grads.biases.resize(layers);
  for (size_t l = layers; l-- > 0;) {
    const Eigen::MatrixXf& in = l == 0 ? inputs : acts[l - 1];
    grads.weights[l].noalias() = delta * in.transpose();
    grads.biases[l] = delta.rowwise().sum();
    if (l > 0) {
      // ReLU's derivative: 1 where the activation (equivalently the pre-activation) is positive
      const Eigen::MatrixXf back = net.weights[l].transpose() * delta;
      delta = (back.array() * (acts[l - 1].array() > 0.0f).cast<float>()).matrix();
    }
  }
  loss += addRegularization(net, reg, grads);
  return loss;
}

double meanSquaredError(const Mlp& net, const Eigen::MatrixXf& inputs,
                        const Eigen::MatrixXf& targets) {
  checkShapes(net);
  checkData(net, inputs, targets);
  if (inputs.cols() == 0) return std::numeric_limits<double>::quiet_NaN();
  double sum = 0.0;
  for (Index start = 0; start < inputs.cols(); start += kChunk) {
    const Index n = std::min(kChunk, inputs.cols() - start);
    const Eigen::MatrixXf y = forward(net, inputs.middleCols(start, n));
    sum += (y - targets.middleCols(start, n)).cast<double>().squaredNorm();
  }
  return sum / static_cast<double>(targets.size());
}

// Non-finite guard: a mini-batch whose loss or gradient is not finite (divergence, or NaN / Inf in
// the data) stops training at once, before its update, so `net` keeps the last parameters that
// gave a finite loss; that epoch is neither logged nor reported. The caller detects this by
// receiving fewer than options.epochs logs. Training also stops (after logging and reporting) an
// epoch whose training-set loss is not finite. An empty training set trains nothing (no logs).
std::vector<EpochLog> train(Mlp& net, const Eigen::MatrixXf& trainInputs,
                            const Eigen::MatrixXf& trainTargets,
                            const Eigen::MatrixXf& validationInputs,
                            const Eigen::MatrixXf& validationTargets, const TrainOptions& options,
                            const std::function<void(const EpochLog&)>& onEpoch) {
  checkShapes(net);
  checkData(net, trainInputs, trainTargets);
  checkData(net, validationInputs, validationTargets);
  MFR_CHECK_GE(options.batchSize, 1);
  std::vector<EpochLog> logs;
  const size_t count = static_cast<size_t>(trainInputs.cols());
  if (count == 0) return logs;

  std::mt19937_64 gen(options.seed);
  std::vector<Index> order(count);
  std::iota(order.begin(), order.end(), Index{0});
  Gradients grads, velocity = zeroGradients(net);
  Eigen::MatrixXf batchInputs, batchTargets;
  const size_t batch = static_cast<size_t>(options.batchSize);
  for (int epoch = 1; epoch <= options.epochs; ++epoch) {
    const auto start = std::chrono::steady_clock::now();
    shuffle(order, gen);
    for (size_t first = 0; first < count; first += batch) {
      const Index n = static_cast<Index>(std::min(batch, count - first));
      gather(trainInputs, order, first, n, batchInputs);
      gather(trainTargets, order, first, n, batchTargets);
      const double loss =
          lossAndGradients(net, batchInputs, batchTargets, options.regularization, grads);
      if (!std::isfinite(loss) || !allFinite(grads)) return logs;
      sgdStep(net, grads, velocity, options.learningRate, options.momentum);
    }
    EpochLog log;
    log.epoch = epoch;
    log.trainLoss = meanSquaredError(net, trainInputs, trainTargets);
    log.validationLoss = meanSquaredError(net, validationInputs, validationTargets);
    log.seconds = secondsSince(start);
    logs.push_back(log);
    if (onEpoch) onEpoch(log);
    if (!std::isfinite(log.trainLoss)) break;
  }
  return logs;
}

}  // namespace mfr::learn
