// `render --resume FILE`: the checkpoint's header decides every setting (docs/ground-truth.md,
// "Resuming"). Options given with --resume may only extend the render (samples, time, checkpoints,
// threads, outputs, messages); a setting that decides the pixels may be repeated with the header's
// value but never changed.
#pragma once

#include "bdptref/checkpoint.h"
#include "cli/render_args.h"
#include "cli/render_record.h"

#include <string>

namespace bdptref::cli {

// Header attribute: the samples the render was asked for, "A:B", or "A:" for no upper end
// (--time alone). A resume without --spp/--sample-range continues to them.
inline constexpr const char* kAttrSamplesRequested = "bdptref:samplesRequested";

// The settings that decide the pixels as the command line gives them (the scene hash is left
// empty: it needs the scene). Throws InputError on a malformed --crop or vector.
ImageSettings settingsFromArgs(const RenderArgs& a);

// Fills every setting not given on the command line from `ck`'s header (scene path, size, camera,
// environment, integrator, MIS, depth, seed, crop, strategy layers, mode, requested samples).
// A setting given with another value than the header's: InputError naming the option and both
// values.
void applyResumeHeader(const FilmFile& ck, RenderArgs& a);

}  // namespace bdptref::cli
