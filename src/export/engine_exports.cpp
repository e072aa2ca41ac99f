#include "export/engine_exports.h"

#include "core/text.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace ff::exporting {

namespace {

std::string num(double v) {
    return text::roundTrip(v);
}
std::string f4(double v) {
    return text::fixed(v, 4);
}

} // namespace

std::string toCsv(const ghosts::GhostTable& t, double angle, std::size_t top) {
    std::ostringstream o;
    o << "Name,Label,SurfaceJ,SurfaceI,FieldAngleDeg,Magnification,RadiusMm,RadiusScreen,FluxR,FluxG,FluxB,Tint,"
         "SurfaceBrightness,GaussianSigmaRadialMm,GaussianSigmaTangentialMm,GaussianFitError,Cos2WRadialMm,"
         "Cos2WTangentialMm,Cos2FitError,SurvivingFraction\n";
    const double halfHeight = 0.5 * t.sensorSizeMm.second;
    for (const GhostSummary& s : summarize(t, angle, top)) {
        o << s.id << ',' << s.label << ',' << s.surfaceJ << ',' << s.surfaceI << ',' << num(angle) << ','
          << num(s.magnification) << ',' << num(s.radiusMm) << ',' << num(s.radiusMm / halfHeight) << ','
          << num(s.flux[0]) << ',' << num(s.flux[1]) << ',' << num(s.flux[2]) << ",\"(R=" << f4(s.tint[0])
          << ",G=" << f4(s.tint[1]) << ",B=" << f4(s.tint[2]) << ",A=1.0)\"," << num(s.surfaceBrightness) << ','
          << num(s.gaussianSigmaR) << ',' << num(s.gaussianSigmaT) << ',' << num(s.gaussianError) << ','
          << num(s.cos2WR) << ',' << num(s.cos2WT) << ',' << num(s.cos2Error) << ',' << num(s.survivingFraction)
          << '\n';
    }
    return o.str();
}

std::string toUnityAsset(const ghosts::GhostTable& t, double angle, std::size_t top, const std::string& name) {
    std::ostringstream o;
    o << "%YAML 1.1\n%TAG !u! tag:unity3d.com,2011:\n--- !u!114 &11400000\nMonoBehaviour:\n"
         "  m_ObjectHideFlags: 0\n  m_CorrespondingSourceObject: {fileID: 0}\n  m_PrefabInstance: {fileID: 0}\n"
         "  m_PrefabAsset: {fileID: 0}\n  m_GameObject: {fileID: 0}\n  m_Enabled: 1\n  m_EditorHideFlags: 0\n"
         "  m_Script: {fileID: 11500000, guid: 877e1507ae8d81c40bf1b94c1a86036f, type: 3}\n"
         "  m_Name: "
      << name << "\n  m_EditorClassIdentifier: \n  elements:\n";
    const bool polygon = t.apertureBlades >= 3;
    for (const GhostSummary& s : summarize(t, angle, top)) {
        // The fitted profile picks the gradient: a soft Gaussian-like ghost fades from the centre, a
        // disc-like (cos^2) one keeps its edge.
        const bool soft = s.gaussianError < s.cos2Error;
        o << "  - visible: 1\n"
          << "    position: " << f4(1.0 - s.magnification) << "\n"
          << "    positionOffset: {x: 0, y: 0}\n    angularOffset: 0\n    translationScale: {x: 1, y: 1}\n"
          << "    m_LocalIntensity: " << f4(s.surfaceBrightness) << "\n"
          << "    lensFlareTexture: {fileID: 0}\n"
          << "    uniformScale: " << f4(20.0 * s.radiusMm / t.sensorSizeMm.second) << "\n"
          << "    sizeXY: {x: 1, y: 1}\n    allowMultipleElement: 0\n    m_Count: 1\n    preserveAspectRatio: 0\n"
          << "    rotation: " << f4(t.bladeRotationDeg) << "\n"
          << "    tint: {r: " << f4(s.tint[0]) << ", g: " << f4(s.tint[1]) << ", b: " << f4(s.tint[2]) << ", a: 1}\n"
          << "    blendMode: 0\n    autoRotate: 0\n"
          << "    flareType: " << (polygon ? 2 : 1) << "\n"
          << "    modulateByLightColor: 1\n"
          << "    m_FallOff: " << (soft ? "1" : "0.25") << "\n"
          << "    m_EdgeOffset: " << (soft ? "0.5" : "0.1") << "\n"
          << "    m_SideCount: " << (polygon ? t.apertureBlades : 6) << "\n"
          << "    m_SdfRoundness: 0\n    inverseSDF: 0\n";
    }
    return o.str();
}

std::string toUnrealPreset(const ghosts::GhostTable& t, double angle) {
    const auto ghosts = summarize(t, angle, 8);
    std::ostringstream o;
    o << "; FourierFlare preset for Unreal Engine's built-in lens flare (Post Process Volume > Lens Flares)\n"
      << "; lens: " << t.lensName << " (" << t.lensFile << "), field angle " << num(angle) << " deg\n"
      << "; Each tint is one ghost copy, scaled about the screen centre by 14 A - 7: a ghost of magnification m has A "
         "= (m + 7) / 14.\n"
      << "; RGB = the ghost's colour x its surface brightness relative to the brightest ghost; set LensFlareIntensity "
         "to taste.\n"
      << "; What this flare cannot express: one bokeh shape and size for all ghosts (LensFlareBokehSize), ghosts with "
         "|m| > 7\n"
      << "; (clamped), per-ghost profiles and spreads, the change of ghosts with the light's position, more than 8 "
         "ghosts.\n";
    double meanRadius = 0.0;
    for (const auto& g : ghosts) meanRadius += g.radiusMm;
    if (!ghosts.empty()) meanRadius /= double(ghosts.size());
    o << "LensFlareIntensity=1.0\n";
    o << "LensFlareBokehSize=" << f4(std::clamp(100.0 * meanRadius / t.sensorSizeMm.first, 0.0, 15.0)) << "\n";
    for (std::size_t i = 0; i < 8; ++i) {
        if (i < ghosts.size()) {
            const auto& g = ghosts[i];
            const double a = std::clamp((g.magnification + 7.0) / 14.0, 0.0, 1.0);
            o << "LensFlareTints[" << i << "]=(R=" << f4(g.tint[0] * g.surfaceBrightness)
              << ",G=" << f4(g.tint[1] * g.surfaceBrightness) << ",B=" << f4(g.tint[2] * g.surfaceBrightness)
              << ",A=" << f4(a) << ")  ; " << g.label << ", m = " << f4(g.magnification) << "\n";
        } else {
            o << "LensFlareTints[" << i << "]=(R=0,G=0,B=0,A=0.5)  ; unused\n";
        }
    }
    return o.str();
}

} // namespace ff::exporting
