// handcentric._figure: the drawings of the package, an extension apart from handcentric._core so
// that `import handcentric` does not load the chart library's shared libraries
// (locate_figure.hpp). handcentric.locate_figure (locate.py) imports it when it draws.
//
// No exception translator here: pybind11's translators are shared by every module built with
// the same pybind11, so one registered here would also translate _core's exceptions (its
// ShapeError and TypeError came back as ValueError once this module was imported). The errors
// are turned into Python's in the function itself.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "handcentric/core/errors.hpp"
#include "locate_figure.hpp"

namespace py = pybind11;

PYBIND11_MODULE(_figure, m) {
  using namespace handcentric;
  m.doc() = "handcentric.locate_figure's drawing (python/locate_figure.hpp).";
  m.def(
      "locate_figure",
      [](const std::vector<std::string>& labels, const std::vector<double>& errors,
         std::optional<std::size_t> first, double relative, const std::string& title,
         const std::string& stem) {
        try {
          python::locate_figure(labels, errors, first, relative, title, stem);
        } catch (const FileError& e) {
          PyErr_SetString(PyExc_OSError, e.what());
          throw py::error_already_set();
        } catch (const Error& e) {
          throw py::value_error(e.what());
        }
      },
      py::arg("labels"), py::arg("errors"), py::arg("first"), py::arg("relative"), py::arg("title"),
      py::arg("stem"), "Writes stem.png and stem.svg (python/locate_figure.hpp).");
}
