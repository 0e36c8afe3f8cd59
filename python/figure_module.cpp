// handcentric._figure: the drawings of the package, an extension apart from handcentric._core so
// that `import handcentric` does not load the chart library's shared libraries
// (locate_figure.hpp). handcentric.locate_figure (locate.py) imports it when it draws.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "handcentric/core/errors.hpp"
#include "locate_figure.hpp"

namespace py = pybind11;

PYBIND11_MODULE(_figure, m) {
  using namespace handcentric;
  m.doc() = "handcentric.locate_figure's drawing (python/locate_figure.hpp).";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InvalidArgument& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const FileError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    }
  });
  m.def("locate_figure", &python::locate_figure, py::arg("labels"), py::arg("errors"),
        py::arg("first"), py::arg("relative"), py::arg("title"), py::arg("stem"),
        "Writes stem.png and stem.svg (python/locate_figure.hpp).");
}
