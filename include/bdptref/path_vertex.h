// A vertex of a camera or light subpath (docs/contracts.md, contract 1). Shared by the megakernel BDPT and
// the wavefront stages, stored as-is in GPU-style buffers: trivially copyable, no pointers.
#pragma once

#include "bdptref/math.h"

#include <cstdint>
#include <type_traits>

namespace bdptref {

enum class VertexType : uint8_t {
    Camera,   // the pinhole (delta position)
    Light,    // a point on a light (or, with `infinite`, a direction to an infinite light)
    Surface,  // a scattering point on the geometry
};

struct PathVertex {
    Vec3 p{0.f};   // position (infinite light: a point far outside the scene along `ng`)
    Vec3 ng{0.f};  // geometric normal (light: emitting normal; infinite light: unit direction from
                   // the scene towards the light; camera: viewing direction)
    Vec3 ns{0.f};  // shading normal (surfaces), = ng elsewhere
    Vec3 wo{0.f};  // unit direction towards the previous vertex of its own subpath (surfaces)
    // directionTo(this vertex, the previous vertex of its subpath) from the stored positions, as
    // the MIS densities use it (wo is the sampled ray's, not the same bits); zero at the first
    // vertex. Written by fillSubpathDensities, which every connection's subpaths pass through.
    Vec3 toPrev{0.f};
    Vec2 bary{0.f};  // surfaces: barycentrics (b1, b2) in `triangle` (textures, vertex colours)
    Rgb beta{0.f};  // throughput of the subpath up to and including this vertex
    // Densities of sampling this vertex from its neighbours: pdfFwd in the direction the subpath
    // was generated, pdfRev in the opposite one. Area measure, except at infinite-light vertices
    // (solid angle). Double so that ratio products do not overflow (docs/contracts.md, contract 3).
    double pdfFwd = 0.0, pdfRev = 0.0;
    // Recursive MIS quantities of the vertex as a connection endpoint (Georgiev et al. 2012's
    // dVCM and dVC restricted to BDPT; docs/mis.md, "The recursive form"), built from the densities
    // above raised to the heuristic's exponent when the subpath's densities are filled in.
    // dVCM: the strategy that samples this vertex from the other side; dVC: all strategies that
    // sample the vertices before it from the other side, waiting for the reverse density at this
    // vertex that the connection provides.
    double dVCM = 0.0, dVC = 0.0;
    int32_t light = -1;     // light index (light vertices, and surfaces lying on an area light)
    uint32_t material = 0;  // surfaces
    uint32_t triangle = 0;  // surfaces and area-light vertices
    VertexType type = VertexType::Surface;
    bool delta = false;     // surfaces: the subpath scattered here through a delta lobe. Endpoints
                            // never set it: a delta light is told by its Light's type.
    bool infinite = false;  // light vertex of a directional or environment light

    bool isOnSurface() const { return ng != Vec3(0.f) && !infinite && type != VertexType::Camera; }
};

static_assert(std::is_trivially_copyable_v<PathVertex>, "PathVertex must be trivially copyable (GPU buffers)");
static_assert(std::is_standard_layout_v<PathVertex>, "PathVertex must have a standard layout");

}  // namespace bdptref
