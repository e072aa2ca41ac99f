#include "python_support.h"

#include "core/error.h"

#include <nlohmann/json.hpp>

#include <exception>

namespace ff::python {

namespace {

// Immortal references: the exception types live as long as the interpreter.
PyObject* errorType = nullptr;
PyObject* inputErrorType = nullptr;
PyObject* usageErrorType = nullptr;

PyObject* newException(py::module_& m, const char* name, PyObject* bases, const char* doc) {
    PyObject* type = PyErr_NewExceptionWithDoc((std::string("fourierflare.") + name).c_str(), doc, bases, nullptr);
    if (!type) throw py::error_already_set();
    m.add_object(name, py::reinterpret_borrow<py::object>(type));
    return type;
}

} // namespace

void registerErrors(py::module_& m) {
    errorType = newException(m, "Error", PyExc_RuntimeError,
                             "A FourierFlare failure. `file`, `line`, `column` locate its cause in an input file "
                             "(0 or '' where not known); `message` is the text without the location.");
    py::tuple valueBases = py::make_tuple(py::handle(errorType), py::handle(PyExc_ValueError));
    inputErrorType = newException(m, "InputError", valueBases.ptr(),
                                  "Malformed or unusable input data (a lens, table or image file, or an array).");
    usageErrorType = newException(m, "UsageError", valueBases.ptr(), "An argument out of its range or unknown.");
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const Error& e) {
            PyObject* type = e.kind() == ErrorKind::Input   ? inputErrorType
                             : e.kind() == ErrorKind::Usage ? usageErrorType
                                                            : errorType;
            py::object exc = py::reinterpret_borrow<py::object>(type)(e.what());
            exc.attr("file") = e.where().file;
            exc.attr("line") = e.where().line;
            exc.attr("column") = e.where().column;
            exc.attr("message") = e.message();
            PyErr_SetObject(type, exc.ptr());
        }
    });
}

void DeferredReporter::report(const Diagnostic& d) {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_.push_back(d);
}

void DeferredReporter::flush() {
    std::vector<Diagnostic> pending;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        pending.swap(pending_);
    }
    if (pending.empty()) return;
    py::object logger = py::module_::import("logging").attr("getLogger")("fourierflare");
    for (const Diagnostic& d : pending) logger.attr(d.severity == Severity::Warning ? "warning" : "info")(d.str());
}

DeferredReporter::~DeferredReporter() = default;

void Interruptible::operator()(std::size_t done, std::size_t total) {
    if (stopped_) throw Interrupted{};
    py::gil_scoped_acquire gil;
    // Another thread's call may have raised while this one waited for the GIL (it sets stopped_
    // holding it): no call after the one that raised.
    if (stopped_) throw Interrupted{};
    try {
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
        if (callback_ && !callback_.is_none()) callback_(done, total);
    } catch (py::error_already_set& e) {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!error_) error_ = std::make_unique<py::error_already_set>(std::move(e));
        stopped_ = true;
        throw Interrupted{};
    }
}

void Interruptible::raise() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!error_) throw std::logic_error("fourierflare: interrupted without a Python error");
    error_->restore();
    throw py::error_already_set();
}

py::array_t<float> ownedArray(std::vector<float>&& data, std::vector<py::ssize_t> shape) {
    auto* owner = new std::vector<float>(std::move(data));
    py::capsule free(owner, [](void* p) { delete static_cast<std::vector<float>*>(p); });
    return py::array_t<float>(shape, owner->data(), free);
}

py::object fromJson(const nlohmann::json& j) {
    switch (j.type()) {
    case nlohmann::json::value_t::null:
        return py::none();
    case nlohmann::json::value_t::boolean:
        return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer:
        return py::int_(j.get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned:
        return py::int_(j.get<std::uint64_t>());
    case nlohmann::json::value_t::number_float:
        return py::float_(j.get<double>());
    case nlohmann::json::value_t::string:
        return py::str(j.get<std::string>());
    case nlohmann::json::value_t::array: {
        py::list l;
        for (const auto& v : j) l.append(fromJson(v));
        return l;
    }
    case nlohmann::json::value_t::object: {
        py::dict d;
        for (const auto& [k, v] : j.items()) d[py::str(k)] = fromJson(v);
        return d;
    }
    default:
        return py::none();
    }
}

namespace {

double finiteNumber(const py::handle& v, const char* what) {
    const double x = py::cast<double>(v);
    if (!std::isfinite(x)) throw Error(ErrorKind::Usage, std::string(what) + " must be a finite number");
    return x;
}

} // namespace

std::vector<ghosts::Light> lightsFrom(const py::handle& lights) {
    std::vector<ghosts::Light> out;
    if (lights.is_none()) return out;
    for (const py::handle& item : lights) {
        ghosts::Light l;
        if (py::isinstance<py::dict>(item)) {
            const py::dict d = py::reinterpret_borrow<py::dict>(item);
            if (!d.contains("x") || !d.contains("y"))
                throw Error(ErrorKind::Usage, "a light given as a dict needs \"x\" and \"y\" (pixels)");
            l.xPx = finiteNumber(d["x"], "a light's x");
            l.yPx = finiteNumber(d["y"], "a light's y");
            if (d.contains("flux")) {
                const py::sequence f = py::reinterpret_borrow<py::sequence>(d["flux"]);
                if (py::len(f) != 3) throw Error(ErrorKind::Usage, "a light's \"flux\" is [r, g, b]");
                for (int c = 0; c < 3; ++c) l.flux[c] = finiteNumber(f[c], "a light's flux");
            }
        } else {
            const py::sequence s = py::reinterpret_borrow<py::sequence>(item);
            const std::size_t n = py::len(s);
            if (n != 2 && n != 5)
                throw Error(ErrorKind::Usage,
                            "a light is (x, y) or (x, y, r, g, b), got " + std::to_string(n) + " numbers");
            l.xPx = finiteNumber(s[0], "a light's x");
            l.yPx = finiteNumber(s[1], "a light's y");
            if (n == 5)
                for (int c = 0; c < 3; ++c) l.flux[c] = finiteNumber(s[2 + c], "a light's flux");
        }
        for (double f : l.flux)
            if (f < 0.0) throw Error(ErrorKind::Usage, "a light's flux must be >= 0");
        out.push_back(l);
    }
    return out;
}

std::pair<int, int> sizeFrom(const py::handle& size, const char* what) {
    const py::sequence s = py::reinterpret_borrow<py::sequence>(size);
    if (py::len(s) != 2) throw Error(ErrorKind::Usage, std::string(what) + " is (width, height) in pixels");
    const int w = py::cast<int>(s[0]), h = py::cast<int>(s[1]);
    if (w < 1 || h < 1 || w > 16384 || h > 16384)
        throw Error(ErrorKind::Usage, std::string(what) + " must be 1..16384 pixels on each side, got " +
                                          std::to_string(w) + " x " + std::to_string(h));
    return {w, h};
}

} // namespace ff::python
