// Shared pieces of the Python module: library errors as mfr.Error, zero-copy numpy arrays over
// moved std::vectors, JSON to Python.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "mfr/core/result.hpp"

namespace mfr::python {

namespace py = pybind11;

/// A library error (Result's message, one line naming the input): raised as mfr.Error.
struct LibraryError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

template <class T>
T unwrap(Result<T>&& result) {
  if (!result) throw LibraryError(result.error().message);
  return std::move(result.value());
}

inline void unwrap(Result<void>&& result) {
  if (!result) throw LibraryError(result.error().message);
}

/// A numpy array over `values`' memory, which the array then owns (a capsule deletes it): no copy.
/// `shape` must multiply to values.size() * componentsPerElement with elements of type `Scalar`.
template <class Scalar, class T>
py::array ownedArray(std::vector<T>&& values, std::vector<py::ssize_t> shape) {
  static_assert(sizeof(T) % sizeof(Scalar) == 0);
  auto* holder = new std::vector<T>(std::move(values));
  py::capsule owner(holder, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<Scalar>(shape, reinterpret_cast<const Scalar*>(holder->data()), owner);
}

/// A path argument: a str or an os.PathLike (pathlib.Path, ...). Else TypeError naming `what`.
inline std::string pathText(const py::object& path, const char* what = "path") {
  if (py::isinstance<py::str>(path)) return path.cast<std::string>();
  if (py::hasattr(path, "__fspath__")) {
    const py::object text = py::module_::import("os").attr("fspath")(path);
    if (py::isinstance<py::str>(text)) return text.cast<std::string>();
  }
  throw py::type_error(std::string(what) + ": expected a str or os.PathLike path");
}

/// What castArgument<T> expects, for its TypeError.
template <class T>
constexpr const char* expectedTypeName() {
  if constexpr (std::is_same_v<T, bool>)
    return "True or False";
  else if constexpr (std::is_integral_v<T>)
    return "an integer";
  else if constexpr (std::is_floating_point_v<T>)
    return "a number";
  else if constexpr (std::is_same_v<T, std::string>)
    return "a str";
  else if constexpr (std::is_same_v<T, py::dict>)
    return "a dict";
  else
    return "another type";
}

/// `value` as T, or a TypeError naming the parameter and the types instead of pybind11's "Unable
/// to cast Python instance to C++ type": "importance['alpha']: expected a number, got str".
template <class T>
T castArgument(py::handle value, const std::string& name) {
  if constexpr (std::is_same_v<T, py::dict>) {
    if (py::isinstance<py::dict>(value)) return py::reinterpret_borrow<py::dict>(value);
  } else {
    py::detail::make_caster<T> caster;
    // a number takes an int (conversion); an integer or a bool takes no str ("5") and no float,
    // and an integer no bool (True is an int)
    const bool boolForInt =
        std::is_integral_v<T> && !std::is_same_v<T, bool> && py::isinstance<py::bool_>(value);
    if (!boolForInt && caster.load(value, std::is_floating_point_v<T>))
      return py::detail::cast_op<T>(std::move(caster));
  }
  throw py::type_error(name + ": expected " + expectedTypeName<T>() + ", got " +
                       std::string(py::str(value.get_type().attr("__name__"))));
}

/// A JSON value as Python objects, exactly as json.loads would read its dump (non-finite numbers
/// become None, as in the files the command line writes).
py::object toPython(const nlohmann::json& value);

void addSceneAndRender(py::module_& m);
void addMetricsAndCompare(py::module_& m);
void addLearn(py::module_& m);

}  // namespace mfr::python
