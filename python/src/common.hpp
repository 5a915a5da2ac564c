// Shared pieces of the Python module: library errors as mfr.Error, zero-copy numpy arrays over
// moved std::vectors, JSON to Python.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
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

// --- arguments ---------------------------------------------------------------------------------
//
// Every function of the module takes its arguments as py::object and converts each one here, so
// that pybind11's dispatcher never fails on a type (its "incompatible function arguments" dump
// of the signature, or "Unable to cast Python instance ...", names no parameter). A conversion
// failure raises TypeError (wrong type), OverflowError (an integer the C++ type cannot hold) or
// ValueError (NaN, infinity, text that is not Unicode, a NUL in a path) naming the parameter;
// namedArguments() puts the function in front: "render(): width: expected an integer, got str".
// Values of the right type but out of the library's range stay the library's mfr.Error, worded
// as the command line's (the library checks them once for both).

/// OverflowError (pybind11 has TypeError and ValueError only).
class overflow_error : public py::builtin_exception {
 public:
  using py::builtin_exception::builtin_exception;
  void set_error() const override { PyErr_SetString(PyExc_OverflowError, what()); }
};

/// The name of `value`'s type, for "expected ..., got TYPE".
inline std::string typeName(py::handle value) {
  return Py_TYPE(value.ptr())->tp_name;
}

/// `value` (an int, float or other) echoed in a message, bounded: a huge integer is described by
/// its size, not written out (Python refuses str() of one over 4300 digits anyway).
inline std::string valueText(py::handle value) {
  if (PyLong_Check(value.ptr())) {
    const auto bits = value.attr("bit_length")().cast<unsigned long long>();
    if (bits > 128)
      return "an integer of about " + std::to_string(bits * 30103 / 100000 + 1) + " digits";
  }
  if (PyLong_Check(value.ptr()) || PyFloat_Check(value.ptr()))
    return std::string(py::str(py::repr(value)));
  return "a value of type " + typeName(value);
}

/// Python's own test for True/False (numpy.bool_ too, as pybind11's bool caster).
inline bool isBool(py::handle value) {
  return PyBool_Check(value.ptr()) ||
         std::strcmp(Py_TYPE(value.ptr())->tp_name, "numpy.bool_") == 0;
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

/// `value` as T, or an error naming the parameter and the type ("importance['alpha']: expected
/// a number, got str"): T is bool (True or False only), an integer type (an int or any object
/// with __index__, not a bool; OverflowError beyond T's range), a floating-point type (an int or
/// a float, finite: ValueError for NaN and infinity), std::string (a str, valid Unicode) or
/// py::dict.
template <class T>
T castArgument(py::handle value, const std::string& name) {
  const auto wrongType = [&]() {
    return py::type_error(name + ": expected " + expectedTypeName<T>() + ", got " +
                          typeName(value));
  };
  PyObject* const object = value.ptr();
  if constexpr (std::is_same_v<T, py::dict>) {
    if (!py::isinstance<py::dict>(value)) throw wrongType();
    return py::reinterpret_borrow<py::dict>(value);
  } else if constexpr (std::is_same_v<T, bool>) {
    if (!isBool(value)) throw wrongType();
    return PyObject_IsTrue(object) == 1;
  } else if constexpr (std::is_integral_v<T>) {
    if (isBool(value) || !PyIndex_Check(object)) throw wrongType();
    const auto index = py::reinterpret_steal<py::object>(PyNumber_Index(object));
    if (!index) throw py::error_already_set();
    int overflow = 0;
    const long long v = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
    if (v == -1 && PyErr_Occurred()) throw py::error_already_set();
    if constexpr (std::is_signed_v<T>) {
      if (overflow == 0 && v >= std::numeric_limits<T>::min() && v <= std::numeric_limits<T>::max())
        return static_cast<T>(v);
    } else {
      if (overflow == 0 && v >= 0 &&
          static_cast<unsigned long long>(v) <= std::numeric_limits<T>::max())
        return static_cast<T>(v);
      if (overflow > 0) {  // past long long: unsigned long long may still hold it
        const unsigned long long u = PyLong_AsUnsignedLongLong(index.ptr());
        if (!PyErr_Occurred() && u <= std::numeric_limits<T>::max()) return static_cast<T>(u);
        PyErr_Clear();
      }
    }
    throw overflow_error(
        name + ": expected an integer in [" + std::to_string(std::numeric_limits<T>::min()) + ", " +
        std::to_string(std::numeric_limits<T>::max()) + "], got " + valueText(index));
  } else if constexpr (std::is_floating_point_v<T>) {
    const PyNumberMethods* number = Py_TYPE(object)->tp_as_number;
    if (isBool(value) || !(PyFloat_Check(object) || PyIndex_Check(object) ||
                           (number != nullptr && number->nb_float != nullptr)))
      throw wrongType();
    const double v = PyFloat_AsDouble(object);
    if (v == -1.0 && PyErr_Occurred()) {
      if (!PyErr_ExceptionMatches(PyExc_OverflowError)) throw py::error_already_set();
      PyErr_Clear();  // an int past the largest double
      throw overflow_error(name + ": expected a finite number, got " + valueText(value));
    }
    if (!std::isfinite(v))
      throw py::value_error(name + ": expected a finite number, got " + valueText(value));
    return static_cast<T>(v);
  } else if constexpr (std::is_same_v<T, std::string>) {
    if (!PyUnicode_Check(object)) throw wrongType();
    Py_ssize_t size = 0;
    const char* text = PyUnicode_AsUTF8AndSize(object, &size);
    if (text == nullptr) {  // lone surrogates (os.fsdecode of bytes that are not UTF-8)
      PyErr_Clear();
      throw py::value_error(name + ": expected text, got a str that is not valid Unicode (" +
                            std::string(py::str(py::repr(value))).substr(0, 80) + ")");
    }
    return std::string(text, static_cast<size_t>(size));
  } else {
    static_assert(std::is_same_v<T, bool>, "castArgument: unsupported type");
  }
}

/// An optional argument: None, or castArgument<T>.
template <class T>
std::optional<T> optionalArgument(py::handle value, const std::string& name) {
  if (value.is_none()) return std::nullopt;
  return castArgument<T>(value, name);
}

/// Whether `value` is a path argument: a str, bytes or an os.PathLike (pathlib.Path, ...).
inline bool isPath(py::handle value) {
  return PyUnicode_Check(value.ptr()) || PyBytes_Check(value.ptr()) ||
         py::hasattr(value, "__fspath__");
}

/// A path argument: a str, bytes or os.PathLike, as the file system's bytes (os.fsencode: a
/// name that is not UTF-8, from os.fsdecode or os.listdir, is the same file). TypeError for
/// another type, ValueError for a NUL byte (Python's open() refuses it too), naming `what`.
inline std::string pathText(const py::object& path, const char* what = "path") {
  if (!isPath(path))
    throw py::type_error(std::string(what) + ": expected a path (str, bytes or os.PathLike), got " +
                         typeName(path));
  auto text = py::reinterpret_steal<py::object>(PyOS_FSPath(path.ptr()));
  if (!text) {  // __fspath__ returned neither str nor bytes
    PyErr_Clear();
    throw py::type_error(std::string(what) + ": expected a path (str, bytes or os.PathLike), got " +
                         typeName(path) + " whose __fspath__ returns neither str nor bytes");
  }
  if (PyUnicode_Check(text.ptr())) {
    text = py::reinterpret_steal<py::object>(PyUnicode_EncodeFSDefault(text.ptr()));
    if (!text) {
      PyErr_Clear();
      throw py::value_error(std::string(what) + ": not encodable as a file name");
    }
  }
  std::string bytes(PyBytes_AS_STRING(text.ptr()),
                    static_cast<size_t>(PyBytes_GET_SIZE(text.ptr())));
  if (bytes.find('\0') != std::string::npos)
    throw py::value_error(std::string(what) + ": a path cannot contain a NUL byte");
  return bytes;
}

/// A file name or scene source as Python text: os.fsdecode of its bytes (a name that is not
/// UTF-8 comes back as the str os.listdir gives for it).
inline py::str pathString(const std::string& bytes) {
  auto text = py::reinterpret_steal<py::str>(
      PyUnicode_DecodeFSDefaultAndSize(bytes.data(), static_cast<Py_ssize_t>(bytes.size())));
  if (!text) throw py::error_already_set();
  return text;
}

/// `function` with every TypeError, ValueError and OverflowError it raises prefixed by `prefix`
/// ("render(): "), so that the message names the function as well as the parameter.
template <class R, class... A>
auto namedArguments(const char* prefix, R (*function)(A...)) {
  return [prefix, function](A... args) -> R {
    try {
      return function(std::forward<A>(args)...);
    } catch (const py::type_error& e) {
      throw py::type_error(prefix + std::string(e.what()));
    } catch (const py::value_error& e) {
      throw py::value_error(prefix + std::string(e.what()));
    } catch (const overflow_error& e) {
      throw overflow_error(prefix + std::string(e.what()));
    }
  };
}

/// A sequence argument (a list, tuple, ... but not a str or bytes) as its items; TypeError
/// naming `name` otherwise.
inline std::vector<py::object> listArgument(py::handle value, const std::string& name,
                                            const char* expected) {
  if (PyUnicode_Check(value.ptr()) || PyBytes_Check(value.ptr()) ||
      !py::isinstance<py::iterable>(value) || py::isinstance<py::dict>(value))
    throw py::type_error(name + ": expected " + expected + ", got " + typeName(value));
  std::vector<py::object> items;
  for (const py::handle item : value) items.push_back(py::reinterpret_borrow<py::object>(item));
  return items;
}

/// An array argument: a numpy array, or a (nested) list or tuple numpy converts; TypeError naming
/// `name` for anything else (a scalar, a str, None) and for a list numpy cannot convert.
inline py::array arrayArgument(py::handle value, const std::string& name, const char* expected) {
  const bool sequence = !PyUnicode_Check(value.ptr()) && !PyBytes_Check(value.ptr()) &&
                        py::isinstance<py::sequence>(value);
  if (!py::isinstance<py::array>(value) && !sequence)
    throw py::type_error(name + ": expected " + expected + ", got " + typeName(value));
  auto array = py::array::ensure(value);
  if (!array)  // e.g. a ragged list
    throw py::type_error(name + ": expected " + expected + ", got " + typeName(value) +
                         " that numpy cannot convert");
  return array;
}

/// What an array holds, for "expected ..., got ...": "an array of dtype <U1", "list (not numbers)".
inline std::string arrayContents(py::handle value, const py::array& array) {
  if (py::isinstance<py::array>(value))
    return "an array of dtype " + std::string(py::str(array.dtype()));
  return typeName(value) + " of " + std::string(py::str(array.dtype()));
}

/// An array of numbers (bool, int, unsigned or float dtype; a list of numbers too) as T,
/// converted as numpy casts: TypeError naming `name` for another type or dtype.
template <class T>
py::array_t<T, py::array::c_style | py::array::forcecast> numberArrayArgument(
    py::handle value, const std::string& name) {
  const py::array array = arrayArgument(value, name, "an array of numbers");
  const char kind = array.dtype().kind();
  if (kind != 'b' && kind != 'i' && kind != 'u' && kind != 'f')
    throw py::type_error(name + ": expected an array of numbers, got " +
                         arrayContents(value, array));
  return py::array_t<T, py::array::c_style | py::array::forcecast>(array);
}

/// A JSON value as Python objects, exactly as json.loads would read its dump (non-finite numbers
/// become None, as in the files the command line writes).
py::object toPython(const nlohmann::json& value);

void addSceneAndRender(py::module_& m);
void addMetricsAndCompare(py::module_& m);
void addLearn(py::module_& m);

}  // namespace mfr::python
