// `bdptref trace --mode wavefront` (docs/trace-and-mis.md): one pixel sample computed by the real
// wavefront scheduler - one pass whose layout holds that pixel alone - and read back from what its
// stages stored: the subpaths from the pool's vertex buffers (after the densities stage), each
// strategy from its connection-queue entry (connect, shadow, finish), L and the splats from the
// accumulate stage. The JSON, the diagnosis of strategies without a contribution and the full
// paths are traceFromSubpaths's, shared with the megakernel trace.
#include "bdptref/errors.h"
#include "bdptref/pass_scheduler.h"
#include "bdptref/renderer.h"
#include "bdptref/scene.h"
#include "bdptref/trace.h"
#include "bdptref/wavefront.h"

#include <map>
#include <memory>
#include <stdexcept>
#include <utility>

namespace bdptref {

namespace {

// Copies what the stages stored for the traced pixel (the only path of the pass).
class StageRecorder final : public WavefrontObserver {
public:
    explicit StageRecorder(uint32_t pixel) : pixel_(pixel) {}

    void subpaths(uint32_t pixel, const PathVertex* camera, int nCamera, const PathVertex* light, int nLight) override {
        if (pixel != pixel_) throw std::logic_error("wavefront trace: the pass computed another pixel");
        ++subpathCalls;
        cameraPath.assign(camera, camera + nCamera);
        lightPath.assign(light, light + nLight);
    }

    void connection(const WavefrontConnectionEntry& e) override {
        if (e.pixel != pixel_) throw std::logic_error("wavefront trace: a connection of another pixel");
        Entry entry;
        entry.record.slot = e.slot;
        entry.record.s = e.s;
        entry.record.t = e.t;
        entry.record.connected = e.connected;
        entry.record.visible = e.unoccluded;
        if (e.connected) {
            entry.pending = *e.pending;
            entry.record.unoccluded = e.pending->unweighted;
            entry.record.shadowRay = e.pending->needsShadowRay;
        }
        if (e.unoccluded) {
            entry.result = *e.result;
            entry.record.weight = e.result->weight;
        }
        if (!bySt.emplace(std::make_pair(e.s, e.t), entries.size()).second)
            throw std::logic_error("wavefront trace: strategy (" + std::to_string(e.s) + "," + std::to_string(e.t) +
                                   ") is twice in the connection queue");
        entries.push_back(entry);
    }

    struct Entry {
        WavefrontQueueRecord record;
        PendingConnection pending{};
        Connection result{};
        bool asked = false;  // the integrator's loop visited it
    };
    int subpathCalls = 0;
    std::vector<PathVertex> cameraPath, lightPath;
    std::vector<Entry> entries;                       // slot order
    std::map<std::pair<int, int>, size_t> bySt;       // (s, t) -> entries index

private:
    uint32_t pixel_;
};

}  // namespace

TracedSample traceSampleWavefront(const Scene& scene, const TraceSettings& settings, int x, int y, uint64_t sample,
                                  const WavefrontOptions* queues) {
    const Camera& camera = scene.camera;
    if (x < camera.cropX0() || x >= camera.cropX1() || y < camera.cropY0() || y >= camera.cropY1())
        throw InputError("pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") is outside the rendered window [" +
                         std::to_string(camera.cropX0()) + ", " + std::to_string(camera.cropX1()) + ") x [" +
                         std::to_string(camera.cropY0()) + ", " + std::to_string(camera.cropY1()) + ")");
    if (settings.integrator != "bdpt" && settings.integrator != "lt")
        throw InputError("--integrator: the wavefront trace replays 'bdpt' or 'lt' samples, got '" + settings.integrator + "'");

    IntegratorSettings is;
    is.maxDepth = settings.bdpt.maxDepth;
    is.rouletteStartDepth = settings.bdpt.rouletteStartDepth;
    is.mis = settings.bdpt.mis;
    is.lightSampler = settings.bdpt.mis.lightSampler;
    is.recordStrategies = true;  // the accumulate stage's weighted value of each entry
    const uint32_t pixel = pixelIndex(x, y, camera.width());
    StageRecorder recorder(pixel);
    WavefrontOptions options = queues ? *queues : WavefrontOptions{};
    options.observer = &recorder;
    WavefrontScheduler scheduler(settings.integrator, is, options);
    const std::unique_ptr<Integrator> integrator = makeIntegrator(settings.integrator, is);  // renderPass's signature

    // A pass over one pixel: one tile of one pixel (the camera, its crop window and the RNG keys
    // are the full image's, so the sample is the one a full render computes).
    PassLayout layout;
    layout.width = camera.width();
    layout.x0 = x;
    layout.y0 = y;
    layout.x1 = x + 1;
    layout.y1 = y + 1;
    layout.tile = 1;
    layout.tilesX = layout.tilesY = 1;
    std::vector<Rgb> passL(layout.windowPixels(), Rgb(0.f));  // the one-pixel window
    std::vector<TileOutput> tiles(1);
    if (!scheduler.renderPass(scene, *integrator, layout, settings.seed, sample, passL, tiles, nullptr))
        throw std::logic_error("wavefront trace: the pass was cancelled");
    if (recorder.subpathCalls != 1) throw std::logic_error("wavefront trace: expected one path in the pass");

    // Each strategy the integrator's loop evaluates is answered by its queue entry.
    const StrategyOutcome fromQueue = [&](int s, int t, Connection* out, PathVertex* sampled) {
        const auto it = recorder.bySt.find({s, t});
        if (it == recorder.bySt.end())
            throw std::logic_error("wavefront trace: strategy (" + std::to_string(s) + "," + std::to_string(t) +
                                   ") is not in the connection queue");
        StageRecorder::Entry& e = recorder.entries[it->second];
        e.asked = true;
        if (!e.record.visible) return false;
        *out = e.result;
        *sampled = e.pending.sampled;
        return true;
    };
    TracedSample traced = traceFromSubpaths(scene, settings, x, y, sample, recorder.cameraPath, recorder.lightPath, fromQueue);
    for (const StageRecorder::Entry& e : recorder.entries)
        if (!e.asked)
            throw std::logic_error("wavefront trace: queue entry (" + std::to_string(e.record.s) + "," +
                                   std::to_string(e.record.t) + ") is not a strategy of the integrator's loop");

    // The accumulate stage's outputs replace the sums traceFromSubpaths formed: they are what the
    // scheduler hands to the film (the test holds them equal to the megakernel's).
    traced.mode = "wavefront";
    traced.L = passL[layout.local(x, y)];
    traced.splats = tiles[0].splats;
    size_t next = 0;  // accumulate records are in slot order, one per visible entry
    for (StageRecorder::Entry& e : recorder.entries) {
        if (!e.record.visible) continue;
        if (next >= tiles[0].strategies.size()) throw std::logic_error("wavefront trace: accumulate skipped an entry");
        const StrategyContribution& c = tiles[0].strategies[next++].second;
        if (c.s != e.record.s || c.t != e.record.t) throw std::logic_error("wavefront trace: accumulate order differs");
        e.record.weighted = c.weighted;
    }
    for (const StageRecorder::Entry& e : recorder.entries) traced.connectionQueue.push_back(e.record);
    return traced;
}

}  // namespace bdptref
