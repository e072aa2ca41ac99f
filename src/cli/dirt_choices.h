#pragma once
// The front element's dirt, shared by the commands that diffract (simulate, render): --aperture-mask
// FILE and --dirt SEED[,DENSITY], multiplied into the iris's pupil (diffraction/pupil_mask.h).

#include "diffraction/pupil_mask.h"

#include <memory>
#include <string>

namespace CLI {
class App;
}

namespace ff::cli {

struct DirtOptions {
    std::string apertureMask; ///< an image of the pupil's transmittance
    std::string dirt;         ///< SEED[,DENSITY]

    void addTo(CLI::App& cmd);
    /// The mask the options give (null: clean). The image is read as a plate is (its size and
    /// channels checked first by `checker`, this program's plate-check); a bad file or value throws
    /// ff::Error (Input or Usage) before anything is written.
    std::shared_ptr<const diffraction::PupilMask> mask(const std::string& checker) const;
};

} // namespace ff::cli
