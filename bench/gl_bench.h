#pragma once
// The GL context a bench process shares, and the rule its GL cases skip by.

#include "gpu/gl_context.h"

#include <benchmark/benchmark.h>

#include <memory>
#include <string>

namespace ff::bench {

/// The process's GL context, labelling `state` with its renderer; null after skipping `state` where
/// there is none, or where `heavy` and the renderer is a software rasteriser (`why` says why there).
inline const gpu::GlContext* glContextFor(benchmark::State& state, bool heavy, const std::string& why) {
    static std::string reason;
    static const std::unique_ptr<gpu::GlContext> context = gpu::GlContext::create(reason);
    if (!context) {
        state.SkipWithError(("no OpenGL 4.5 context: " + reason).c_str());
        return nullptr;
    }
    if (heavy && !context->hardware()) {
        state.SkipWithError(("software rasteriser: skipped (" + why + ")").c_str());
        return nullptr;
    }
    state.SetLabel(context->renderer());
    return context.get();
}

} // namespace ff::bench
