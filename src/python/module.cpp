// The Python module `fourierflare` (docs/python.md).

#include "ff/version.h"

#include "bindings.h"
#include "python_support.h"

PYBIND11_MODULE(fourierflare, m) {
    m.doc() = R"(FourierFlare: physically based lens flares from real lens prescriptions.

Lengths in millimetres, wavelengths in nanometres, angles in degrees, image positions in pixels
(origin top-left, +y down). Images are float32 numpy arrays of shape (height, width, channels).
Errors raise fourierflare.Error (InputError, UsageError) carrying file, line and column.)";
    m.attr("__version__") = ff::kVersion;
    ff::python::registerErrors(m);
    ff::python::bindLens(m);
    ff::python::bindGhosts(m);
    ff::python::bindRender(m);
    ff::python::bindSimulate(m);
    ff::python::bindCompare(m);
}
