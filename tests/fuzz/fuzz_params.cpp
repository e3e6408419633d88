// libFuzzer target for the data-file and scene readers: JSON text ->
// parseJsonText -> ParamReader -> the struct loaders (tire, road, integrator,
// rigid body, double-wishbone corner) -> requireAllKeysRead; and the same text
// as a scene file (SceneDescription::check: vehicle, plugins, analysis, keys). Any outcome but success or a
// vdyn::Error (a named user error) is a finding: another exception type, a
// crash, or a sanitizer report. Build and run: tests/fuzz/run_fuzz.sh.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <string>

#include "vdyn/core/integrators.h"
#include "vdyn/core/params.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/tire/road.h"
#include "vdyn/tire/tire_model.h"
#include "vdyn/vehicles/double_wishbone.h"
#include "vdyn/vehicles/wheeled_vehicle.h"
#include "vdyn/vehicles/standard_registry.h"

using namespace vdyn;

namespace {
template <class F>
void guarded(F&& f) {
  try {
    f();
  } catch (const Error&) {
    // a named user error: the reader's intended answer to bad input
  } catch (const std::exception& e) {
    std::fprintf(stderr, "unnamed exception (not vdyn::Error): %s\n", e.what());
    std::abort();
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  guarded([&] {
    const Json j = parseJsonText(text, "fuzz.json");
    if (!j.is_object()) return;
    const ParamReader r = ParamReader::fromJson(j, "fuzz.json");
    guarded([&] { BrushTireParams::fromParams(r); });
    guarded([&] { LinearTireParams::fromParams(r); });
    guarded([&] { if (r.has("road")) RoadParams::fromParams(r.child("road")); });
    guarded([&] { if (r.has("integrator")) IntegratorSettings::fromParams(r.child("integrator")); });
    guarded([&] { if (r.has("chassis")) RigidBodyParams::fromParams(r.child("chassis")); });
    guarded([&] {
      if (r.has("axles")) WheeledVehicleParams::fromParams(r);
    });
    guarded([&] {
      if (r.has("rows"))
        for (const ParamReader& row : r.array("rows")) row.integer("n"), row.booleanOr("b", false), row.vec3Or("v", {});
    });
    guarded([&] {
      if (r.has("patch")) {
        const ParamReader m = r.mergedWith(r.child("patch"));
        m.numberOr("x", 0);
        m.requireAllKeysRead();
      }
    });
    guarded([&] {
      // A scene: only texts that name a known vehicle type get built (each
      // build is a Simbody system); the rest is checked up to the vehicle.
      SceneDescription::fromJson(j, "fuzz_scene.json", standardRegistry()).check();
    });
    r.requireAllKeysRead();
  });
  return 0;
}
