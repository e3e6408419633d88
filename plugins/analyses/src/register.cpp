#include "vdyn/analyses/analyses.h"

namespace vdyn {

void registerTransientAnalysis(PluginRegistry& registry);
void registerSteadyAnalyses(PluginRegistry& registry);
void registerSensitivityAnalysis(PluginRegistry& registry);
void registerOptimalRatioAnalysis(PluginRegistry& registry);

void registerAnalyses(PluginRegistry& registry) {
  registerTransientAnalysis(registry);
  registerSteadyAnalyses(registry);
  registerSensitivityAnalysis(registry);
  registerOptimalRatioAnalysis(registry);
}

}  // namespace vdyn
