// flexure._flexure: the C++ side of `import flexure`. It only loads scenes (from text, a file or
// the catalog) and hands them to the pipeline every front end calls (pipeline::Study); the
// Python package (python/flexure) builds the scene text from arrays and keywords, and turns the
// JSON and the buffers given here into numpy arrays. Arrays cross as Python buffers (the buffer
// protocol), not through pybind11/numpy.h: that works with NumPy 1 and 2 alike.
//
// Long calls run without the GIL. Every 20 ms they take it back for a moment to let Python
// handle its signals (Ctrl-C) and to call the caller's progress function; either can stop the
// computation at its next step or frame, which then returns what it has with `stopped` set.
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <chrono>
#include <cstring>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "engine/interrupt.h"
#include "engine/model.h"
#include "engine/resources.h"
#include "pipeline/pipeline.h"
#include "present/output_file.h"
#include "present/path_output.h"
#include "present/report.h"
#include "present/text.h"
#include "render/image.h"
#include "render/provenance.h"
#include "render/renderer.h"
#include "render/video.h"
#include "scenes/catalog.h"
#include "scenes/importers.h"
#include "scenes/keys.h"
#include "scenes/scene.h"
#include "scenes/scene_edit.h"

namespace py = pybind11;
using namespace flexure;

namespace {

// A block of numbers handed to Python through the buffer protocol (numpy.asarray views it
// without a copy).
template <typename T>
struct Block {
  std::vector<T> data;
  std::vector<py::ssize_t> shape;
};

template <typename T>
py::buffer_info bufferOf(Block<T>& b) {
  std::vector<py::ssize_t> strides(b.shape.size());
  py::ssize_t s = sizeof(T);
  for (size_t i = b.shape.size(); i-- > 0;) {
    strides[i] = s;
    s *= b.shape[i];
  }
  return py::buffer_info(b.data.data(), sizeof(T), py::format_descriptor<T>::format(), static_cast<py::ssize_t>(b.shape.size()),
                         b.shape, strides);
}

using Doubles = Block<double>;
using Bytes = Block<std::uint8_t>;

// One renderer per process, made on first use (an OSMesa context is expensive to make), used by
// one thread at a time: every call that may draw holds drawing_mutex (Python threads run
// them without the GIL).
std::mutex drawing_mutex;
render::Renderer& sharedRenderer() {
  static std::unique_ptr<render::Renderer> r;
  if (!r) {
    try {
      r = std::make_unique<render::Renderer>();
    } catch (const std::runtime_error& e) {
      throw present::OutputError(std::string("cannot render: ") + e.what());
    }
  }
  return *r;
}

// Progress and Ctrl-C while the GIL is released. `report(stage, done, total)` is the caller's
// function (None: none); it returns False to stop. A KeyboardInterrupt stops too and is
// remembered, so that the caller can raise it with what was computed.
class Watch {
 public:
  explicit Watch(py::object report) : report_(std::move(report)) {}
  bool operator()(pipeline::Stage stage, int done, int total) {
    const auto now = std::chrono::steady_clock::now();
    const bool last = done >= total;
    if (!last && now - last_ < std::chrono::milliseconds(20)) return !stopped_;
    last_ = now;
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) {
      // Python's handler raised (KeyboardInterrupt): keep it for later, stop now.
      interrupted_ = true;
      stopped_ = true;
      PyErr_Clear();
      return false;
    }
    if (!report_.is_none()) {
      static const char* names[] = {"tracking", "other_paths", "frames"};
      try {
        const py::object r = report_(names[static_cast<int>(stage)], done, total);
        if (!r.is_none() && !r.cast<bool>()) stopped_ = true;
      } catch (py::error_already_set& e) {
        error_ = std::make_unique<py::error_already_set>(std::move(e));
        stopped_ = true;
      }
    }
    return !stopped_;
  }
  bool stopped() const { return stopped_; }
  bool interrupted() const { return interrupted_; }
  // The caller's progress function raised: raise it again (with the GIL held).
  void rethrow() {
    if (error_) {
      auto e = std::move(error_);
      throw std::move(*e);
    }
  }

 private:
  py::object report_;
  std::chrono::steady_clock::time_point last_{};
  bool stopped_ = false, interrupted_ = false;
  std::unique_ptr<py::error_already_set> error_;
};

// A loaded scene: what the Python System keeps. Immutable once loaded.
struct PyScene {
  std::shared_ptr<const scenes::Scene> scene;
};

// Python counts vertices from 0: the package hands over 0-based scene text (a file that counts
// from 1 is read, then written again from 0), so labels, pairs and pictures count from 0.
std::shared_ptr<const scenes::Scene> adopt(scenes::Scene&& s) {
  return std::make_shared<const scenes::Scene>(std::move(s));
}

// A study of one scene (its analysis, motion, projection), computed once each.
struct PyStudy {
  std::shared_ptr<const scenes::Scene> scene;
  std::unique_ptr<Watch> watch;
  std::unique_ptr<pipeline::Study> study;
  PyStudy(std::shared_ptr<const scenes::Scene> s, std::optional<int> steps, std::optional<std::uint64_t> seed,
          py::object report)
      : scene(std::move(s)), watch(std::make_unique<Watch>(std::move(report))) {
    pipeline::StudyOptions o;
    o.steps = steps;
    o.projection_seed = seed;
    Watch* w = watch.get();
    o.progress = [w](pipeline::Stage stage, int done, int total) { return (*w)(stage, done, total); };
    study = std::make_unique<pipeline::Study>(*scene, o);
  }
  // After a call that released the GIL: the caller's exception, if its function raised.
  void check() { watch->rethrow(); }
};

py::dict pathResult(PyStudy& st) {
  const engine::DeformationPath& path = st.study->motion().path;
  const engine::ConstraintSystem& sys = st.scene->model->system();
  const int n = sys.numVertices(), d = sys.dimension();
  auto samples = std::make_shared<Doubles>();
  samples->shape = {static_cast<py::ssize_t>(path.samples.size()), n, d};
  samples->data.resize(path.samples.size() * static_cast<size_t>(n) * d);
  for (size_t i = 0; i < path.samples.size(); ++i) {
    const engine::Matrix p = sys.vertexPositions(path.samples[i]);  // d x n, column-major
    std::memcpy(samples->data.data() + i * n * d, p.data(), sizeof(double) * n * d);
  }
  py::dict r;
  r["meta"] = present::jsonText(present::pathJson(*st.scene, path, false));
  r["samples"] = py::cast(samples);
  r["stopped"] = st.watch->stopped();
  r["interrupted"] = st.watch->interrupted();
  return r;
}

std::shared_ptr<Bytes> imageBlock(const render::Image& image) {
  auto b = std::make_shared<Bytes>();
  b->shape = {image.height, image.width, 4};
  b->data = image.rgba;
  return b;
}

}  // namespace

PYBIND11_MODULE(_flexure, m) {
  m.doc() = "flexure's engine and pipeline (use the flexure package, not this module)";
  m.attr("version") = FLEXURE_VERSION;
  m.attr("commit") = render::flexureCommit();
  // The provenance every JSON output carries (render/provenance.h): the Python program's
  // command line, after "python".
  {
    std::vector<std::string> words{"python"};
    try {
      for (const py::handle a : py::module_::import("sys").attr("argv")) words.push_back(py::str(a));
    } catch (const py::error_already_set&) {
      // no sys.argv (an embedded interpreter): "python" alone
    }
    render::setCommandLine(std::move(words));
  }

  py::class_<Doubles, std::shared_ptr<Doubles>>(m, "_Doubles", py::buffer_protocol())
      .def_buffer([](Doubles& b) { return bufferOf(b); });
  py::class_<Bytes, std::shared_ptr<Bytes>>(m, "_Bytes", py::buffer_protocol())
      .def_buffer([](Bytes& b) { return bufferOf(b); });

  // Errors: the C++ exceptions become the package's (flexure.errors), made here with the
  // fields the Python side needs to name the key.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const scenes::SceneError& e) {
      py::object cls = py::module_::import("flexure.errors").attr("_SceneErrorFromLoader");
      py::object err = cls(e.file, e.line, e.column, e.message, e.item >= 0 ? py::object(py::int_(e.item)) : py::object(py::none()));
      PyErr_SetObject(err.get_type().ptr(), err.ptr());
    } catch (const present::OutputError& e) {
      py::object cls = py::module_::import("flexure.errors").attr("OutputError");
      PyErr_SetObject(cls.ptr(), py::str(e.what()).ptr());
    } catch (const render::VideoInterrupted&) {
      py::object cls = py::module_::import("flexure.errors").attr("Interrupted");
      PyErr_SetObject(cls.ptr(), py::str("stopped while writing the frames; nothing was written").ptr());
    } catch (const engine::ResourceError& e) {
      py::object cls = py::module_::import("flexure.errors").attr("TooLargeError");
      PyErr_SetObject(cls.ptr(), py::str(e.what()).ptr());
    } catch (const engine::ModelError& e) {
      py::object cls = py::module_::import("flexure.errors").attr("FlexureError");
      PyErr_SetObject(cls.ptr(), py::str(e.what()).ptr());
    } catch (const nlohmann::json::exception& e) {  // a JSON value of the wrong type, wherever read
      py::object cls = py::module_::import("flexure.errors").attr("FlexureError");
      PyErr_SetObject(cls.ptr(), py::str(e.what()).ptr());
    }
  });

  py::class_<PyScene>(m, "_Scene")
      .def_property_readonly("type", [](const PyScene& s) { return s.scene->type; })
      .def_property_readonly("title", [](const PyScene& s) { return s.scene->title; })
      .def_property_readonly("ghost", [](const PyScene& s) { return s.scene->render.style.ghost; })
      .def_property_readonly("motion_steps", [](const PyScene& s) { return s.scene->motion.steps; })
      .def_property_readonly("dimension", [](const PyScene& s) { return s.scene->model->system().dimension(); })
      .def_property_readonly("num_vertices", [](const PyScene& s) { return s.scene->model->system().numVertices(); })
      .def("vertices",
           [](const PyScene& s) {
             const engine::Model& model = *s.scene->model;
             const engine::Matrix p = model.system().vertexPositions(model.startCoordinates());
             auto b = std::make_shared<Doubles>();
             b->shape = {p.cols(), p.rows()};
             b->data.assign(p.data(), p.data() + p.size());
             return b;
           })
      .def(
          "analyze",
          [](const PyScene& s) {
            engine::RigidityReport rep;
            bool interrupted = false;
            {
              py::gil_scoped_release nogil;
              // Ctrl-C: the analysis stops at its next stage or motion-check step (Python's
              // handler runs every 20 ms, with the GIL taken for it) and the KeyboardInterrupt
              // it raised is raised here.
              auto last = std::chrono::steady_clock::now();
              engine::InterruptCheck check([&] {
                const auto now = std::chrono::steady_clock::now();
                if (now - last < std::chrono::milliseconds(20)) return false;
                last = now;
                py::gil_scoped_acquire gil;
                interrupted = PyErr_CheckSignals() != 0;
                return interrupted;
              });
              try {
                rep = pipeline::analyze(*s.scene);
              } catch (const engine::Interrupted&) {
              }
            }
            if (interrupted) throw py::error_already_set();
            return py::make_tuple(present::jsonText(present::analysisJson(*s.scene, rep), 2),
                                  present::analysisText(*s.scene, rep));
          },
          "the analysis JSON (as `flexure analyze --json` prints it) and the text report (as `flexure analyze`)")
      .def(
          "jacobian",
          [](const PyScene& s) {
            // The matrix whose rank the analysis reports: the equations' Jacobian at the start
            // over the free coordinates, as triplets, with a label per row and per column.
            const engine::Model& model = *s.scene->model;
            const engine::ConstraintSystem& sys = model.system();
            const engine::SparseMatrix J = sys.jacobian(model.startCoordinates());
            std::vector<long> rows, cols;
            std::vector<double> values;
            for (int c = 0; c < J.outerSize(); ++c)
              for (engine::SparseMatrix::InnerIterator it(J, c); it; ++it) {
                rows.push_back(it.row());
                cols.push_back(it.col());
                values.push_back(it.value());
              }
            // A column's label: the vertex coordinate it is ("x3"), or "" (a system's own
            // variable, such as a facet's normal): the blocks' variable indices, inverted.
            std::vector<std::string> columns(static_cast<size_t>(sys.numVariables()));
            const char axis[] = {'x', 'y', 'z'};
            for (int v = 0; v < sys.numVertices(); ++v)
              for (int k = 0; k < sys.dimension() && k < 3; ++k)
                if (const int c = sys.variableIndex(v, k); c >= 0)
                  columns[static_cast<size_t>(c)] = std::string(1, axis[k]) + std::to_string(v + s.scene->index_base);
            return py::make_tuple(rows, cols, values, J.rows(), J.cols(), sys.equationLabels(s.scene->index_base),
                                  columns);
          },
          "the Jacobian at the start as triplets (rows, cols, values, m, n) with row and column labels")
      .def(
          "track",
          [](const PyScene& s, py::object report) {
            auto st = std::make_shared<PyStudy>(s.scene, std::nullopt, std::nullopt, std::move(report));
            {
              py::gil_scoped_release nogil;
              st->study->motion();
            }
            st->check();
            py::dict r = pathResult(*st);
            r["study"] = py::cast(st);
            return r;
          },
          py::arg("report"))
      .def("study",
           [](const PyScene& s, std::optional<int> steps, std::optional<std::uint64_t> seed, py::object report) {
             return std::make_shared<PyStudy>(s.scene, steps, seed, std::move(report));
           });

  py::class_<PyStudy, std::shared_ptr<PyStudy>>(m, "_Study")
      .def("path_json",
           [](PyStudy& st) { return present::jsonText(present::pathJson(*st.scene, st.study->motion().path), 1) + "\n"; })
      .def("path_csv", [](PyStudy& st) { return present::pathCsv(*st.scene, st.study->motion().path); })
      .def("interrupted", [](PyStudy& st) { return st.watch->interrupted(); })
      .def(
          "write",
          [](PyStudy& st, const std::string& kind, const std::string& file, int sample, bool flex,
             const std::string& data, const std::vector<int>& samples) {
            const auto k = scenes::parseOutputKind(kind);
            if (!k) throw std::invalid_argument("unknown output kind '" + kind + "'");
            // A filmstrip: several samples in one figure, as `render --samples`.
            if (samples.size() > 64) throw std::invalid_argument("samples: at most 64 samples in one figure");
            scenes::OutputSpec spec{file, *k, sample, flex, samples};
            present::Written w;
            {
              py::gil_scoped_release nogil;
              std::lock_guard<std::mutex> lock(drawing_mutex);
              w = st.study->write(spec, file, sharedRenderer, data);
            }
            st.check();
            return py::make_tuple(w.file, w.summary, w.seconds);
          },
          py::arg("kind"), py::arg("file"), py::arg("sample") = 0, py::arg("flex") = false, py::arg("data") = "",
          py::arg("samples") = std::vector<int>{})
      .def(
          "image",
          [](PyStudy& st, const std::string& kind, int sample, bool flex) {
            const auto k = scenes::parseOutputKind(kind);
            if (!k) throw std::invalid_argument("unknown output kind '" + kind + "'");
            render::Image image;
            {
              py::gil_scoped_release nogil;
              std::lock_guard<std::mutex> lock(drawing_mutex);
              image = st.study->image({"", *k, sample, flex}, sharedRenderer);
            }
            st.check();
            return imageBlock(image);
          },
          py::arg("kind"), py::arg("sample") = 0, py::arg("flex") = false)
      .def("png",
           [](PyStudy& st, int sample, bool flex) {
             std::vector<std::uint8_t> png;
             {
               py::gil_scoped_release nogil;
               std::lock_guard<std::mutex> lock(drawing_mutex);
               png = render::encodePng(st.study->image({"", scenes::OutputKind::Frame, sample, flex}, sharedRenderer));
             }
             st.check();
             return py::bytes(reinterpret_cast<const char*>(png.data()), png.size());
           })
      .def("frames",
           [](PyStudy& st) {
             std::vector<std::shared_ptr<Bytes>> frames;
             {
               py::gil_scoped_release nogil;
               std::lock_guard<std::mutex> lock(drawing_mutex);
               st.study->animationFrames(sharedRenderer,
                                         [&](int, const render::Image& image) { frames.push_back(imageBlock(image)); });
             }
             st.check();
             return frames;
           });

  m.def(
      "load_text",
      [](const std::string& text, const std::string& source, const py::list& arrays) {
        // [system] arrays as numbers: (key, buffer) pairs of C-contiguous float64 or int64 arrays
        // of 1 or 2 dimensions, each `KEY = []` in the text. Copied once, not written as text.
        std::vector<scenes::SceneArray> given;
        for (const py::handle& item : arrays) {
          const auto pair = item.cast<py::tuple>();
          scenes::SceneArray g;
          g.key = pair[0].cast<std::string>();
          const py::buffer_info b = pair[1].cast<py::buffer>().request();
          const bool is_double = b.format == py::format_descriptor<double>::format();
          const bool is_int = b.format == py::format_descriptor<std::int64_t>::format() || b.format == "l" || b.format == "q";
          if ((!is_double && !is_int) || (b.ndim != 1 && b.ndim != 2) || b.itemsize != 8 ||
              b.strides.back() != 8 || (b.ndim == 2 && b.strides[0] != 8 * b.shape[1]))
            throw std::invalid_argument("load_text: " + g.key + " must be a C-contiguous float64 or int64 array of 1 or 2 dimensions");
          g.rows = static_cast<size_t>(b.shape[0]);
          g.cols = b.ndim == 2 ? static_cast<size_t>(b.shape[1]) : 0;
          g.integer = is_int;
          const size_t n = static_cast<size_t>(b.size);
          g.values.resize(n);
          if (is_double) {
            std::memcpy(g.values.data(), b.ptr, n * sizeof(double));
          } else {
            const auto* p = static_cast<const std::int64_t*>(b.ptr);
            for (size_t i = 0; i < n; ++i) g.values[i] = static_cast<double>(p[i]);
          }
          given.push_back(std::move(g));
        }
        scenes::Scene s;
        {
          py::gil_scoped_release nogil;
          s = scenes::loadSceneFromString(text, source, std::move(given));
        }
        return PyScene{adopt(std::move(s))};
      },
      py::arg("text"), py::arg("source"), py::arg("arrays") = py::list());
  m.def(
      "load_file",
      [](const std::string& path) {
        scenes::Scene s;
        {
          py::gil_scoped_release nogil;
          s = scenes::loadScene(path);
        }
        return PyScene{adopt(std::move(s))};
      },
      py::arg("path"));
  m.def("is_importable", &scenes::isImportable, "a file name that [system] from (and load) reads");
  m.def("read_scene_file", &scenes::readSceneFile, "a scene file's text (SceneError when it cannot be read)");
  m.def("catalog", [] {
    py::list l;
    for (const auto& e : scenes::catalog()) l.append(py::make_tuple(e.name, e.text));
    return l;
  });
  m.def(
      "index_keys",
      [] {
        // From the key table (scenes/keys.cpp), in its order; [system]'s of every system type.
        py::dict d;
        for (const scenes::KeySpec& k : scenes::sceneKeys())
          if (k.vertex_indices && !d.contains(k.table))
            d[py::str(k.table)] = py::tuple(py::cast(scenes::indexKeysOf(k.table)));
        return d;
      },
      "the keys that hold vertex numbers (counted from index_base), by table: {table: (key, ...)}");
}
