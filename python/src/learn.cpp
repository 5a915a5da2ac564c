// The deep k-buffer's learning side in Python: .mfrnn models from and to numpy weight arrays (so a
// network trained in numpy or PyTorch runs in dkb unchanged) and .mfrds datasets as numpy arrays.
#include <cmath>
#include <cstddef>

#include "common.hpp"
#include "mfr/cpu/deep_importance.hpp"
#include "mfr/learn/dataset.hpp"
#include "mfr/learn/mlp.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/dkb_features.hpp"

namespace mfr::python {
namespace {

using learn::Model;
using RowMajor = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

constexpr size_t kMaxLayers = 16;  // model_file.hpp
constexpr py::ssize_t kMaxLayerSize = 4096;

std::string shapeText(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

/// Model from weights[l] (out x in) and biases[l] (out), checked so that an mfr.Model is always a
/// valid network (the library would abort on mismatched shapes).
std::shared_ptr<Model> makeModel(const py::object& weightsArg, const py::object& biasesArg,
                                 const py::object& metadataArg) {
  const std::vector<py::object> weights =
      listArgument(weightsArg, "weights", "a list of weight arrays");
  const std::vector<py::object> biases = listArgument(biasesArg, "biases", "a list of bias arrays");
  const std::string metadata = castArgument<std::string>(metadataArg, "metadata");
  if (weights.empty() || weights.size() > kMaxLayers)
    throw py::value_error("weights: expected 1 to 16 layers, got " +
                          std::to_string(weights.size()));
  if (biases.size() != weights.size())
    throw py::value_error("biases: one per layer: " + std::to_string(weights.size()) +
                          " weight matrices but " + std::to_string(biases.size()) + " biases");
  auto model = std::make_shared<Model>();
  learn::Mlp& net = model->net;
  for (size_t l = 0; l < weights.size(); ++l) {
    const FloatArray w =
        numberArrayArgument<float>(weights[l], "weights[" + std::to_string(l) + "]");
    const FloatArray b = numberArrayArgument<float>(biases[l], "biases[" + std::to_string(l) + "]");
    const std::string layer = "layer " + std::to_string(l);
    if (w.ndim() != 2)
      throw py::value_error("weights[" + std::to_string(l) +
                            "]: expected a 2-D (outputs, inputs) array, got shape " + shapeText(w));
    const py::ssize_t outputs = w.shape(0), inputs = w.shape(1);
    if (outputs < 1 || inputs < 1 || outputs > kMaxLayerSize || inputs > kMaxLayerSize)
      throw py::value_error("weights[" + std::to_string(l) + "]: layer sizes must be in [1, 4096]");
    if (l == 0) net.sizes.push_back(static_cast<int>(inputs));
    if (inputs != net.sizes.back())
      throw py::value_error("weights[" + std::to_string(l) + "]: shape " + shapeText(w) +
                            " takes " + std::to_string(inputs) + " inputs but the previous layer " +
                            "has " + std::to_string(net.sizes.back()) + " outputs");
    if (b.ndim() != 1 || b.shape(0) != outputs)
      throw py::value_error("biases[" + std::to_string(l) + "]: expected shape (" +
                            std::to_string(outputs) + ",), got " + shapeText(b));
    net.sizes.push_back(static_cast<int>(outputs));
    net.weights.emplace_back(Eigen::Map<const RowMajor>(w.data(), outputs, inputs));
    net.biases.emplace_back(Eigen::Map<const Eigen::VectorXf>(b.data(), outputs));
    if (!net.weights.back().allFinite() || !net.biases.back().allFinite())
      throw py::value_error(layer + ": weights and biases must be finite");
  }
  // what save() and load() refuse (checkDkbModel, too): too long, not UTF-8, nested too deeply
  if (const std::string problem = learn::metadataProblem(metadata); !problem.empty())
    throw py::value_error(problem);
  model->metadata = metadata;
  return model;
}

/// A read-only view of a column-major Eigen matrix owned by the Python object `owner`.
py::array matrixView(const Eigen::MatrixXf& m, py::handle owner) {
  py::array a(
      py::dtype::of<float>(), {m.rows(), m.cols()},
      {static_cast<py::ssize_t>(sizeof(float)), static_cast<py::ssize_t>(sizeof(float) * m.rows())},
      m.data(), owner);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

py::array vectorView(const Eigen::VectorXf& v, py::handle owner) {
  py::array a(py::dtype::of<float>(), {v.size()}, {static_cast<py::ssize_t>(sizeof(float))},
              v.data(), owner);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

py::array predict(const Model& model, const py::object& featuresArg) {
  const FloatArray features = numberArrayArgument<float>(featuresArg, "features");
  const learn::Mlp& net = model.net;
  if (features.ndim() != 2 || features.shape(1) != net.inputs())
    throw py::value_error("features: expected shape (N, " + std::to_string(net.inputs()) +
                          "), got " + shapeText(features));
  const size_t count = static_cast<size_t>(features.shape(0));
  std::vector<float> out(count * static_cast<size_t>(net.outputs()));
  {
    py::gil_scoped_release release;
    if (count > 0) learn::predictRows(net, features.data(), count, out.data());
  }
  return ownedArray<float>(
      std::move(out), {static_cast<py::ssize_t>(count), static_cast<py::ssize_t>(net.outputs())});
}

std::shared_ptr<Model> loadModel(const py::object& pathArg) {
  const std::string path = pathText(pathArg);
  py::gil_scoped_release release;
  return std::make_shared<Model>(unwrap(learn::readModel(path)));
}

// --- datasets ---------------------------------------------------------------------------------

static_assert(alignof(learn::DatasetSample) == 4 && sizeof(learn::DatasetSample) % 4 == 0,
              "DatasetSample: floats and u32 only (strided views below)");

/// A read-only strided view into the samples (owned by `owner`).
template <class Scalar>
py::array sampleField(const std::vector<learn::DatasetSample>& samples, size_t offset, int columns,
                      py::handle owner) {
  const auto* base = reinterpret_cast<const std::byte*>(samples.data()) + offset;
  const py::ssize_t n = static_cast<py::ssize_t>(samples.size());
  const py::ssize_t stride = sizeof(learn::DatasetSample);
  std::vector<py::ssize_t> shape{n}, strides{stride};
  if (columns > 1) {
    shape.push_back(columns);
    strides.push_back(sizeof(Scalar));
  }
  py::array a(py::dtype::of<Scalar>(), shape, strides, reinterpret_cast<const Scalar*>(base),
              owner);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

py::dict loadDataset(const py::object& pathArg, bool check) {
  const std::string path = pathText(pathArg);
  auto data = std::make_shared<learn::Dataset>();
  {
    py::gil_scoped_release release;
    *data = unwrap(learn::readDataset(path));
    if (check) unwrap(learn::checkDatasetDefinitions(*data, path));
  }
  py::dict d;
  d["scenes"] = data->scenes;
  d["metadata"] = data->metadata;
  d["file_hash"] = learn::hashHex(data->fileHash);
  // every array is a view into the one sample buffer, which the capsule frees with the last view
  auto* holder = new std::shared_ptr<learn::Dataset>(data);
  py::capsule owner(holder,
                    [](void* p) { delete static_cast<std::shared_ptr<learn::Dataset>*>(p); });
  const auto& s = data->samples;
  using Sample = learn::DatasetSample;
  d["features"] = sampleField<float>(s, offsetof(Sample, features), kDkbFeatureCount, owner);
  d["targets"] = sampleField<float>(s, offsetof(Sample, target), 1, owner);
  d["scene"] = sampleField<uint32_t>(s, offsetof(Sample, scene), 1, owner);
  d["view"] = sampleField<uint32_t>(s, offsetof(Sample, view), 1, owner);
  d["budget_step"] = sampleField<uint32_t>(s, offsetof(Sample, budgetStep), 1, owner);
  d["pixel"] = sampleField<uint32_t>(s, offsetof(Sample, pixel), 1, owner);
  return d;
}

using UintArray = py::array_t<uint32_t, py::array::c_style | py::array::forcecast>;

/// None, or a column of per-sample indices: integers in [0, 2^32 - 1] (numpy would wrap -1 to
/// 4294967295 silently).
py::object indexColumnArgument(const py::object& column, const char* name) {
  if (column.is_none()) return column;
  const py::array array = arrayArgument(column, name, "an array of integers");
  const char kind = array.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throw py::type_error(std::string(name) + ": expected an array of integers, got " +
                         arrayContents(column, array));
  if (array.size() > 0 &&
      (array.attr("min")() < py::int_(0) || array.attr("max")() > py::int_(UINT32_MAX)))
    throw overflow_error(std::string(name) + ": values must be in [0, 4294967295]");
  return array;
}

void saveDataset(const py::object& pathArg, const py::array& featuresArg,
                 const py::array& targetsArg, const std::vector<std::string>& scenes,
                 const py::object& sceneArg, const py::object& viewArg,
                 const py::object& budgetStepArg, const py::object& pixelArg,
                 const std::string& metadata) {
  const std::string path = pathText(pathArg);
  const FloatArray features(featuresArg), targets(targetsArg);
  if (features.ndim() != 2 || features.shape(1) != kDkbFeatureCount)
    throw py::value_error("features: expected shape (N, 12), got " + shapeText(features));
  const py::ssize_t n = features.shape(0);
  if (targets.ndim() != 1 || targets.shape(0) != n)
    throw py::value_error("targets: expected shape (" + std::to_string(n) + ",), got " +
                          shapeText(targets));
  if (scenes.empty() || scenes.size() > 65536)
    throw py::value_error("scenes: expected 1 to 65536 scene names");
  for (const std::string& name : scenes)
    if (name.empty() || name.size() > 4096)
      throw py::value_error("scenes: names must be 1 to 4096 bytes long");
  if (const std::string problem = learn::metadataProblem(metadata); !problem.empty())
    throw py::value_error(problem);  // as readDataset and writeDataset refuse it
  const auto column = [&](const py::object& arg, const char* name) {
    if (arg.is_none()) return UintArray(std::vector<py::ssize_t>{n});  // zeros below
    UintArray a(arg);
    if (a.ndim() != 1 || a.shape(0) != n)
      throw py::value_error(std::string(name) + ": expected shape (" + std::to_string(n) +
                            ",), got " + shapeText(a));
    return a;
  };
  const UintArray scene = column(sceneArg, "scene"), view = column(viewArg, "view"),
                  step = column(budgetStepArg, "budget_step"), pixel = column(pixelArg, "pixel");
  const auto f = features.unchecked<2>();
  const auto t = targets.unchecked<1>();
  learn::Dataset data;
  data.scenes = scenes;
  data.metadata = metadata;
  data.samples.resize(static_cast<size_t>(n));
  for (py::ssize_t i = 0; i < n; ++i) {
    learn::DatasetSample& s = data.samples[static_cast<size_t>(i)];
    s.scene = sceneArg.is_none() ? 0 : scene.at(i);
    s.view = viewArg.is_none() ? 0 : view.at(i);
    s.budgetStep = budgetStepArg.is_none() ? 0 : step.at(i);
    s.pixel = pixelArg.is_none() ? 0 : pixel.at(i);
    if (s.scene >= scenes.size())
      throw py::value_error("scene[" + std::to_string(i) + "] = " + std::to_string(s.scene) +
                            ": there are " + std::to_string(scenes.size()) + " scenes");
    for (int c = 0; c < kDkbFeatureCount; ++c) s.features[c] = f(i, c);
    s.target = t(i);
    // the check load_dataset and mfr train apply (readDataset): e.g. a target outside [0, 1]
    if (const auto problem = learn::datasetSampleProblem(s, 1, scenes.size()))
      throw py::value_error(std::string(problem->field) + "[" + std::to_string(i) +
                            "]: " + problem->text);
  }
  py::gil_scoped_release release;
  unwrap(learn::writeDataset(path, data));
}

}  // namespace

void addLearn(py::module_& m) {
  m.attr("FEATURE_COUNT") = kDkbFeatureCount;
  m.attr("FEATURE_SET") = kDkbFeatureSet;
  m.attr("TARGET_SCALING") = learn::kDkbTargetScaling;
  m.attr("DKB_LAYERS") = learn::kDkbLayers;

  py::class_<Model, std::shared_ptr<Model>>(
      m, "Model",
      "A multilayer perceptron as a .mfrnn file holds it: ReLU hidden layers, sigmoid output. "
      "weights[l] has shape (outputs, inputs) and biases[l] (outputs,): y = W x + b.")
      .def(py::init(namedArguments("Model(): ", &makeModel)), py::arg("weights"), py::arg("biases"),
           py::arg("metadata"),
           "From numpy arrays (any real dtype, stored as float32) and a JSON metadata text. "
           "Raises ValueError for inconsistent shapes or non-finite values.")
      .def_static("load", namedArguments("Model.load(): ", &loadModel), py::arg("path"),
                  "Reads a .mfrnn file (mfr.Error if bad).")
      .def("save",
           namedArguments(
               "Model.save(): ",
               +[](const Model& model, const py::object& pathArg) {
                 const std::string path = pathText(pathArg);
                 py::gil_scoped_release release;
                 unwrap(learn::writeModel(path, model));
               }),
           py::arg("path"), "Writes the .mfrnn file (include/mfr/learn/model_file.hpp).")
      .def(
          "to_bytes",
          [](const Model& model) {
            const std::vector<uint8_t> bytes = learn::encodeModel(model);
            return py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size());
          },
          "The .mfrnn file's bytes.")
      .def("predict", namedArguments("Model.predict(): ", &predict), py::arg("features"),
           "The network's output for float (N, inputs) features: float32 (N, outputs), computed "
           "by the library (as dkb does).")
      .def(
          "check_dkb", [](const Model& model) { unwrap(checkDkbModel(model, "(mfr.Model)")); },
          "Raises mfr.Error unless the deep k-buffer can use the model (12 inputs, 1 output, "
          "metadata declaring FEATURE_SET and, if any, TARGET_SCALING).")
      .def_property_readonly("sizes", [](const Model& model) { return model.net.sizes; })
      .def_property_readonly(
          "weights",
          [](py::object self) {
            const Model& model = self.cast<const Model&>();
            py::list l;
            for (const Eigen::MatrixXf& w : model.net.weights) l.append(matrixView(w, self));
            return l;
          },
          "Read-only float32 views (outputs, inputs) of the weight matrices.")
      .def_property_readonly(
          "biases",
          [](py::object self) {
            const Model& model = self.cast<const Model&>();
            py::list l;
            for (const Eigen::VectorXf& b : model.net.biases) l.append(vectorView(b, self));
            return l;
          },
          "Read-only float32 views of the bias vectors.")
      .def_readonly("metadata", &Model::metadata, "The JSON metadata text.")
      .def_property_readonly("parameter_count",
                             [](const Model& model) { return model.net.parameterCount(); })
      .def("__repr__", [](const Model& model) {
        std::string text = "<mfr.Model";
        char separator = ' ';
        for (int s : model.net.sizes) {
          text += separator;
          text += std::to_string(s);
          separator = '-';
        }
        text += '>';
        return text;
      });

  m.def(
      "builtin_model",
      []() {
        auto model = unwrap(builtinDkbModel());
        return std::make_shared<Model>(*model);
      },
      "The model dkb uses without model= (models/dkb-default.mfrnn, compiled into the library).");
  // the arguments converted here, named, before the work
  m.def("_load_dataset",
        namedArguments(
            "load_dataset(): ",
            +[](const py::object& path, const py::object& check) {
              return loadDataset(path, castArgument<bool>(check, "check"));
            }),
        py::arg("path"), py::arg("check"));
  m.def("_save_dataset",
        namedArguments(
            "save_dataset(): ",
            +[](const py::object& path, const py::object& features, const py::object& targets,
                const py::object& scenes, const py::object& scene, const py::object& view,
                const py::object& budgetStep, const py::object& pixel, const py::object& metadata) {
              std::vector<std::string> names;
              for (const py::object& name : listArgument(scenes, "scenes", "a list of str"))
                names.push_back(castArgument<std::string>(
                    name, "scenes[" + std::to_string(names.size()) + "]"));
              saveDataset(path, numberArrayArgument<float>(features, "features"),
                          numberArrayArgument<float>(targets, "targets"), names,
                          indexColumnArgument(scene, "scene"), indexColumnArgument(view, "view"),
                          indexColumnArgument(budgetStep, "budget_step"),
                          indexColumnArgument(pixel, "pixel"),
                          castArgument<std::string>(metadata, "metadata"));
            }),
        py::arg("path"), py::arg("features"), py::arg("targets"), py::arg("scenes"),
        py::arg("scene"), py::arg("view"), py::arg("budget_step"), py::arg("pixel"),
        py::arg("metadata"));
}

}  // namespace mfr::python
