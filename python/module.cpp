// bdptref._bdptref: the pybind11 binding of bdptref.h (docs/library.md). Images and paths are
// NumPy arrays; errors are bdptref.InputError (a ValueError) with the CLI's messages. The Python
// layer in bdptref/__init__.py adds keyword-friendly wrappers; everything numeric happens here.
#include "bdptref/bdptref.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>

namespace py = pybind11;
using namespace bdptref;

namespace {

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

MisSettings misSettings(const std::string& heuristic, double beta) {
    MisSettings m;
    m.heuristic = parseMisHeuristic(heuristic);
    m.beta = beta;
    return m;
}

// MisReport as a dict of NumPy arrays (one entry per strategy s = 0..n-1).
py::dict misDict(const MisReport& r) {
    const size_t n = r.strategies.size();
    py::array_t<double> w(n), logp(n);
    py::array_t<bool> valid(n);
    py::array_t<int> s(n), t(n);
    py::list reasons;
    for (size_t i = 0; i < n; ++i) {
        const StrategyVerdict& v = r.strategies[i];
        w.mutable_at(i) = v.weight;
        logp.mutable_at(i) = v.logDensity;
        valid.mutable_at(i) = v.valid;
        s.mutable_at(i) = v.s;
        t.mutable_at(i) = v.t;
        reasons.append(v.reason);
    }
    py::dict d;
    d["form"] = r.form;
    d["weights"] = w;
    d["valid"] = valid;
    d["s"] = s;
    d["t"] = t;
    d["reasons"] = reasons;
    d["log_density"] = logp;
    d["sum"] = r.sum;
    d["heuristic"] = misHeuristicName(r.mis.heuristic);
    d["beta"] = r.mis.beta;
    d["produced_by"] = r.producedBy;
    d["warnings"] = r.warnings;
    return d;
}

py::dict misDensities(const DoubleArray& pdfCamera, const DoubleArray& pdfLight, double pdfNextEvent, py::object delta,
                      bool deltaLight, const std::string& heuristic, double beta) {
    if (pdfCamera.ndim() != 1 || pdfLight.ndim() != 1 || pdfCamera.shape(0) != pdfLight.shape(0))
        throw InputError("pdf_camera and pdf_light must be 1-D arrays of the same length (one entry per vertex, camera first)");
    PathDensities p;
    const size_t n = size_t(pdfCamera.shape(0));
    p.vertices.resize(n);
    std::vector<bool> deltas(n, false);
    if (!delta.is_none()) {
        const auto d = delta.cast<py::array_t<bool, py::array::c_style | py::array::forcecast>>();
        if (d.ndim() != 1 || size_t(d.shape(0)) != n) throw InputError("delta must be a 1-D array with one entry per vertex");
        for (size_t i = 0; i < n; ++i) deltas[i] = d.at(i);
    }
    for (size_t i = 0; i < n; ++i) p.vertices[i] = {pdfCamera.at(i), pdfLight.at(i), deltas[i]};
    p.lightNextEvent = pdfNextEvent;
    p.deltaLight = deltaLight;
    return misDict(misWeights(p, misSettings(heuristic, beta)));
}

MisPathOptions pathOptions(const std::string& form, const std::string& scene, int width, int height, py::object heuristic,
                           py::object beta, py::object lightSampler) {
    MisPathOptions o;
    o.form = form;
    o.sceneFile = scene;
    o.width = width;
    o.height = height;
    if (!heuristic.is_none()) {
        o.overrideHeuristic = true;
        o.heuristic = parseMisHeuristic(heuristic.cast<std::string>());
    }
    if (!beta.is_none()) {
        o.overrideBeta = true;
        o.beta = beta.cast<double>();
    }
    if (!lightSampler.is_none()) {
        o.overrideLightSampler = true;
        o.lightSampler = parseLightSamplerKind(lightSampler.cast<std::string>(), "light_sampler");
    }
    return o;
}

// (H, W, 3) -> interleaved floats, checked against the expected shape.
const float* rgbData(const FloatArray& a, int width, int height, const char* what) {
    if (a.ndim() != 3 || a.shape(2) != 3 || (width > 0 && (a.shape(0) != height || a.shape(1) != width)))
        throw InputError(std::string(what) + ": expected an array of shape (height, width, 3)");
    return a.data();
}

ExrImage imageFromNumpy(const FloatArray& mean, py::object variance, py::object count) {
    const float* m = rgbData(mean, 0, 0, "mean");
    const int h = int(mean.shape(0)), w = int(mean.shape(1));
    FloatArray var, cnt;
    const float* v = nullptr;
    const float* c = nullptr;
    if (!variance.is_none()) {
        var = variance.cast<FloatArray>();
        v = rgbData(var, w, h, "variance");
    }
    if (!count.is_none()) {
        cnt = count.cast<FloatArray>();
        if (cnt.ndim() != 2 || cnt.shape(0) != h || cnt.shape(1) != w)
            throw InputError("count: expected an array of shape (height, width)");
        c = cnt.data();
    }
    return imageFromArrays(w, h, m, v, c);
}

py::array_t<float> channelArray(const ExrImage& im, const std::string& name) {
    const auto it = im.channels.find(name);
    if (it == im.channels.end()) throw InputError("the image has no channel '" + name + "'");
    py::array_t<float> a({im.height, im.width});
    std::memcpy(a.mutable_data(), it->second.data(), it->second.size() * sizeof(float));
    return a;
}

py::array_t<float> rgbArray(const ExrImage& im, const std::string& prefix) {
    py::array_t<float> a({im.height, im.width, 3});
    static const char* const kRgb[3] = {"R", "G", "B"};
    float* out = a.mutable_data();
    for (int c = 0; c < 3; ++c) {
        const auto it = im.channels.find(prefix + kRgb[c]);
        if (it == im.channels.end()) throw InputError("the image has no channel '" + prefix + kRgb[c] + "'");
        for (size_t i = 0; i < it->second.size(); ++i) out[3 * i + size_t(c)] = it->second[i];
    }
    return a;
}

template <typename F>
py::array_t<double> filmRgb(const Film& f, F value) {
    py::array_t<double> a({f.height(), f.width(), 3});
    double* out = a.mutable_data();
    for (int y = 0; y < f.height(); ++y)
        for (int x = 0; x < f.width(); ++x) {
            const DVec3 v = value(x, y);
            double* p = out + 3 * (size_t(y) * size_t(f.width()) + size_t(x));
            p[0] = v.x;
            p[1] = v.y;
            p[2] = v.z;
        }
    return a;
}

py::array_t<float> mapArray(const std::vector<float>& v, int w, int h) {
    py::array_t<float> a({h, w});
    if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(float));
    return a;
}

ExrMetadata metadataFromDict(const py::dict& d) {
    ExrMetadata md;
    for (const auto& kv : d) {
        const std::string key = kv.first.cast<std::string>();
        if (py::isinstance<py::bool_>(kv.second) || py::isinstance<py::int_>(kv.second))
            md.ints.emplace_back(key, kv.second.cast<int>());
        else if (py::isinstance<py::float_>(kv.second))
            md.floats.emplace_back(key, kv.second.cast<float>());
        else
            md.strings.emplace_back(key, py::str(kv.second).cast<std::string>());
    }
    return md;
}

}  // namespace

PYBIND11_MODULE(_bdptref, m) {
    m.doc() = "bdptref: MIS weights of paths, the calibrated image comparison, EXR films and in-process "
              "rendering (docs/library.md)";
    py::register_exception<InputError>(m, "InputError", PyExc_ValueError);
    m.attr("__version__") = BDPTREF_VERSION;
    m.attr("git_revision") = BDPTREF_GIT_REVISION;

    // ---- MIS weights
    m.def("mis_weights_densities", &misDensities, py::arg("pdf_camera"), py::arg("pdf_light"), py::arg("pdf_next_event"),
          py::arg("delta") = py::none(), py::arg("delta_light") = false, py::arg("heuristic") = "balance",
          py::arg("beta") = 2.0,
          "MIS weights of every strategy s = 0..n-1 of a path given by explicit per-vertex densities "
          "(docs/trace-and-mis.md, densities form): pdf_camera[i] = p->(x_i), pdf_light[i] = p<-(x_i) "
          "(x_0 = camera first), pdf_next_event = NEE density of the light endpoint, delta = per-vertex "
          "delta flags. Returns a dict: weights, valid, s, t, reasons, log_density, sum.");
    m.def(
        "mis_weights_json",
        [](const std::string& text, const std::string& form, const std::string& scene, int width, int height,
           py::object heuristic, py::object beta, py::object lightSampler) {
            const MisPathOptions o = pathOptions(form, scene, width, height, heuristic, beta, lightSampler);
            MisReport r;
            {
                py::gil_scoped_release release;
                r = misWeightsOfPathJson(text, o);
            }
            return misDict(r);
        },
        py::arg("json_text"), py::arg("form") = "auto", py::arg("scene") = "", py::arg("width") = 0, py::arg("height") = 0,
        py::arg("heuristic") = py::none(), py::arg("beta") = py::none(), py::arg("light_sampler") = py::none(),
        "MIS weights of a path in the 'bdptref-path' JSON format (what `bdptref mis` reads): the scene "
        "form (vertices with positions, normals, materials, lights, against the scene) or the densities form. "
        "light_sampler: 'power' or 'tree' overrides the path's recorded next-event light choice (--light-sampler).");
    m.def(
        "mis_weights_file",
        [](const std::string& file, const std::string& form, const std::string& scene, int width, int height,
           py::object heuristic, py::object beta, int s, int t, py::object lightSampler) {
            const MisPathOptions o = pathOptions(form, scene, width, height, heuristic, beta, lightSampler);
            MisReport r;
            {
                py::gil_scoped_release release;
                r = misWeightsOfPathFile(file, o, s, t);
            }
            return misDict(r);
        },
        py::arg("path"), py::arg("form") = "auto", py::arg("scene") = "", py::arg("width") = 0, py::arg("height") = 0,
        py::arg("heuristic") = py::none(), py::arg("beta") = py::none(), py::arg("s") = -1, py::arg("t") = -1,
        py::arg("light_sampler") = py::none(),
        "`bdptref mis FILE`: MIS weights of a path file ('bdptref-path', or a 'bdptref-trace' with s, t); "
        "light_sampler as in mis_weights_json.");

    // ---- images and comparison
    py::class_<ExrImage>(m, "Image", "An image as the comparison reads it: channels R, G, B, optionally "
                                     "variance.R/G/B (variance of the mean) and count.")
        .def_readonly("width", &ExrImage::width)
        .def_readonly("height", &ExrImage::height)
        .def_property_readonly("channels", [](const ExrImage& im) {
            std::vector<std::string> names;
            for (const auto& kv : im.channels) names.push_back(kv.first);
            return names;
        })
        .def_readonly("attributes", &ExrImage::attributes)
        .def("channel", &channelArray, py::arg("name"), "One channel as a (height, width) float32 array.")
        .def_property_readonly("mean", [](const ExrImage& im) { return rgbArray(im, ""); }, "(height, width, 3) R, G, B")
        .def_property_readonly("variance", [](const ExrImage& im) { return rgbArray(im, "variance."); },
                               "(height, width, 3) variance of the mean");
    m.def("image", &imageFromNumpy, py::arg("mean"), py::arg("variance") = py::none(), py::arg("count") = py::none(),
          "An Image from NumPy arrays: mean (H, W, 3), variance of the mean (H, W, 3), count (H, W).");
    m.def("read_image", &readImage, py::arg("path"), "Reads an EXR (or anything OpenImageIO reads) as an Image.");

    py::class_<CompareResult>(m, "CompareResult", "The outcome of the calibrated comparison (docs/compare.md).")
        .def_readonly("has_verdict", &CompareResult::hasVerdict)
        .def_readonly("consistent", &CompareResult::consistent, "meaningful only when has_verdict")
        .def_readonly("p_value", &CompareResult::pGlobal, "global p-value (Sidak over the local and bias tests)")
        .def_readonly("p_local", &CompareResult::pLocal)
        .def_readonly("p_bias", &CompareResult::pBias)
        .def_readonly("tested", &CompareResult::tested)
        .def_readonly("flagged", &CompareResult::flagged, "number of flagged pixels")
        .def_readonly("sentence", &CompareResult::sentence)
        .def_readonly("no_verdict_reason", &CompareResult::noVerdictReason)
        .def_readonly("warnings", &CompareResult::warnings)
        .def_property_readonly("test_kind", [](const CompareResult& r) { return std::string(testKindName(r.kind)); })
        .def_property_readonly("flagged_mask",
                               [](const CompareResult& r) {
                                   py::array_t<bool> a({r.height, r.width});
                                   for (size_t i = 0; i < r.isFlagged.size(); ++i) a.mutable_data()[i] = r.isFlagged[i] != 0;
                                   return a;
                               },
                               "(height, width) bool: the flagged pixels")
        .def_property_readonly("pixel_p", [](const CompareResult& r) { return mapArray(r.pixelP, r.width, r.height); },
                               "(height, width) pixel p-values (NaN where not tested)")
        .def_property_readonly("pixel_z", [](const CompareResult& r) { return mapArray(r.pixelZ, r.width, r.height); })
        .def("report", [](const CompareResult& r) { return formatCompareReport(r); }, "the text report of `bdptref compare`")
        .def("json", [](const CompareResult& r) { return compareResultJson(r); }, "the JSON of `bdptref compare --json`")
        .def("__bool__", [](const CompareResult& r) { return r.hasVerdict && r.consistent; })
        .def("__repr__", [](const CompareResult& r) { return "<bdptref.CompareResult: " + r.sentence + ">"; });

    auto compareOptions = [](double alpha, double epsilon, double minEffective, double precision) {
        CompareOptions o;
        o.alpha = alpha;
        o.epsilon = epsilon;
        o.minEffectiveSamples = minEffective;
        o.precision = precision;
        return o;
    };
    m.def(
        "compare_images",
        [compareOptions](const ExrImage& test, const ExrImage& ref, double alpha, double epsilon, double minEffective,
                         double precision) {
            const CompareOptions o = compareOptions(alpha, epsilon, minEffective, precision);
            py::gil_scoped_release release;
            return compareImages(test, ref, o);
        },
        py::arg("test"), py::arg("reference"), py::arg("alpha") = 0.01, py::arg("epsilon") = 1e-2,
        py::arg("min_effective") = 10.0, py::arg("precision") = 1e-5,
        "`bdptref compare TEST REF`: is `test` consistent with `reference` up to Monte Carlo noise?");

    py::class_<RenderSetComparison>(m, "RenderSetComparison", "A set of renders each compared with one reference.")
        .def_readonly("results", &RenderSetComparison::results)
        .def_readonly("p_value", &RenderSetComparison::pSet, "Sidak over the renders of the smallest global p")
        .def_readonly("worst", &RenderSetComparison::worst)
        .def_readonly("has_verdict", &RenderSetComparison::hasVerdict)
        .def_readonly("consistent", &RenderSetComparison::consistent)
        .def_readonly("sentence", &RenderSetComparison::sentence)
        .def("__bool__", [](const RenderSetComparison& r) { return r.hasVerdict && r.consistent; });
    m.def(
        "compare_set",
        [compareOptions](const std::vector<ExrImage>& renders, const ExrImage& ref, double alpha, double epsilon,
                         double minEffective, double precision) {
            const CompareOptions o = compareOptions(alpha, epsilon, minEffective, precision);
            py::gil_scoped_release release;
            return compareRenderSet(renders, ref, o);
        },
        py::arg("renders"), py::arg("reference"), py::arg("alpha") = 0.01, py::arg("epsilon") = 1e-2,
        py::arg("min_effective") = 10.0, py::arg("precision") = 1e-5,
        "Compares each render of a set with the reference; the set's p-value is Sidak-combined.");

    // ---- films, scenes, rendering
    py::class_<Film>(m, "Film", "Per-pixel double sums, sums of squares and counts (docs/exr.md).")
        .def(py::init<int, int>(), py::arg("width"), py::arg("height"))
        .def_property_readonly("width", &Film::width)
        .def_property_readonly("height", &Film::height)
        .def("add_pass",
             [](Film& f, const FloatArray& values) {
                 // One sample per pixel, recorded as the next pixel-sample index (as renderImage
                 // does), so the film's exact state stays consistent and can be written and read back.
                 const float* v = rgbData(values, f.width(), f.height(), "values");
                 for (int y = 0; y < f.height(); ++y)
                     for (int x = 0; x < f.width(); ++x) {
                         const float* p = v + 3 * (size_t(y) * size_t(f.width()) + size_t(x));
                         f.addSample(x, y, Rgb(p[0], p[1], p[2]));
                     }
                 const uint64_t next = f.samples().endIndex();
                 f.samples().add({next, next + 1});
             },
             py::arg("values"), "Adds one sample to every pixel: values is a (height, width, 3) array.")
        .def_property_readonly("mean", [](const Film& f) { return filmRgb(f, [&](int x, int y) { return f.mean(x, y); }); },
                               "(height, width, 3) float64 pixel mean")
        .def_property_readonly("variance",
                               [](const Film& f) { return filmRgb(f, [&](int x, int y) { return f.varianceOfMean(x, y); }); },
                               "(height, width, 3) variance of the mean (s^2/n)")
        .def_property_readonly("light_mean",
                               [](const Film& f) { return filmRgb(f, [&](int x, int y) { return f.lightMean(x, y); }); })
        .def_property_readonly("count",
                               [](const Film& f) {
                                   py::array_t<uint64_t> a({f.height(), f.width()});
                                   for (int y = 0; y < f.height(); ++y)
                                       for (int x = 0; x < f.width(); ++x)
                                           a.mutable_at(y, x) = f.count(x, y);
                                   return a;
                               })
        .def("strategy_mean",
             [](const Film& f, int s, int t, bool weighted) {
                 if (!f.strategies().enabled() || s < 0 || t < 1 || s + t - 2 > f.strategies().maxDepth())
                     throw InputError("the film has no layer for strategy (" + std::to_string(s) + ", " + std::to_string(t) + ")");
                 return filmRgb(f, [&](int x, int y) { return f.strategies().mean(s, t, weighted, x, y); });
             },
             py::arg("s"), py::arg("t"), py::arg("weighted") = true, "(height, width, 3) mean of one (s,t) layer")
        .def_property_readonly("samples", [](const Film& f) { return f.samples().text(); }, "the sample ranges held")
        .def_property_readonly("non_finite_samples", &Film::nonFiniteSamples)
        .def("image", [](const Film& f) {
            std::vector<float> mean(f.pixelCount() * 3), var(f.pixelCount() * 3), count(f.pixelCount());
            for (int y = 0; y < f.height(); ++y)
                for (int x = 0; x < f.width(); ++x) {
                    const size_t i = size_t(y) * size_t(f.width()) + size_t(x);
                    const DVec3 mu = f.mean(x, y), v = f.varianceOfMean(x, y);
                    for (int c = 0; c < 3; ++c) {
                        mean[3 * i + size_t(c)] = float(mu[c]);
                        var[3 * i + size_t(c)] = float(v[c]);
                    }
                    count[i] = float(f.count(x, y));
                }
            return imageFromArrays(f.width(), f.height(), mean.data(), var.data(), count.data());
        }, "The film as an Image for compare_images (mean, variance, count).");

    py::class_<FilmFile>(m, "FilmFile", "A film read back bit for bit with its header attributes.")
        .def_readonly("path", &FilmFile::path)
        .def_readonly("film", &FilmFile::film)
        .def_readonly("attributes", &FilmFile::attributes)
        .def_readonly("light_layer", &FilmFile::lightLayer);
    m.def("read_film", &readFilmExr, py::arg("path"), "Reads a bdptref EXR film (render, checkpoint, merge) bit for bit.");
    m.def(
        "write_film",
        [](const std::string& path, const Film& film, const py::dict& metadata, bool lightLayer) {
            writeFilm(path, film, metadataFromDict(metadata), lightLayer);
        },
        py::arg("path"), py::arg("film"), py::arg("metadata") = py::dict(), py::arg("light_layer") = false,
        "Writes a film as `bdptref render` does (atomically; bdptref:version recorded). metadata: "
        "{name: str | int | float} header attributes.");

    py::class_<Scene>(m, "Scene", "A loaded, finalized glTF scene.")
        .def_property_readonly("path", [](const Scene& s) { return s.info.path; })
        .def_property_readonly("content_hash", [](const Scene& s) { return s.info.contentHash; })
        .def_property_readonly("width", [](const Scene& s) { return s.camera.width(); })
        .def_property_readonly("height", [](const Scene& s) { return s.camera.height(); })
        .def_property_readonly("warnings", [](const Scene& s) { return s.info.warnings; });
    m.def(
        "load_scene",
        [](const std::string& file, int width, int height, const std::string& env, const std::string& cameraPos,
           const std::string& cameraTarget, const std::string& cameraUp, double fov, const std::string& crop) {
            SceneReference r;
            r.file = file;
            r.width = width;
            r.height = height;
            r.env = env;
            r.cameraPos = cameraPos;
            r.cameraTarget = cameraTarget;
            r.cameraUp = cameraUp;
            r.fov = fov;
            r.crop = crop;
            py::gil_scoped_release release;
            return loadSceneFile(r);
        },
        py::arg("path"), py::arg("width") = 256, py::arg("height") = 256, py::arg("env") = "", py::arg("camera_pos") = "",
        py::arg("camera_target") = "", py::arg("camera_up") = "0,1,0", py::arg("fov") = 0.0, py::arg("crop") = "",
        "Loads a glTF scene with the options of `bdptref render` (strings as on the command line).");
    m.def(
        "render",
        [](const Scene& scene, const std::string& integrator, int spp, uint32_t seed, int maxDepth,
           const std::string& heuristic, double beta, bool strategies, int threads, uint64_t firstSample,
           const std::string& lightSampler) {
            RenderJob job;
            job.settings.lightSampler = parseLightSamplerKind(lightSampler, "light_sampler");
            job.integrator = integrator;
            job.spp = spp;
            job.seed = seed;
            job.settings.maxDepth = maxDepth;
            job.settings.mis = misSettings(heuristic, beta);
            job.settings.recordStrategies = strategies;
            job.threads = threads;
            job.firstSample = firstSample;
            py::gil_scoped_release release;
            return renderScene(scene, job);
        },
        py::arg("scene"), py::arg("integrator") = "bdpt", py::arg("spp") = 16, py::arg("seed") = 0,
        py::arg("max_depth") = 64, py::arg("mis") = "balance", py::arg("beta") = 2.0, py::arg("strategies") = false,
        py::arg("threads") = 0, py::arg("first_sample") = 0, py::arg("light_sampler") = "power",
        "Renders the scene into a new Film in-process: the pixels `bdptref render` computes with these settings. "
        "light_sampler: 'power' or 'tree' (as --light-sampler: path and bdpt; lt refuses the tree).");
}
