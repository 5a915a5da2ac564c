#include "mfr/method/stats_json.hpp"

namespace mfr {

nlohmann::json statsToJson(const RenderStats& s) {
  nlohmann::json j;
  j["method"] = s.method;
  j["budget_bytes"] = s.budgetBytes ? nlohmann::json(*s.budgetBytes) : nlohmann::json(nullptr);
  j["bytes_used"] = s.bytesUsed;
  j["bytes_by_category"] = s.bytesByCategory;
  j["bytes_allocated"] = s.bytesAllocated;
  j["bytes_allocated_by_category"] = s.bytesAllocatedByCategory;
  j["fragment_slots"] = s.fragmentSlots;
  j["fragments_generated"] = s.fragmentsGenerated;
  j["fragments_captured"] = s.captured;
  j["fragments_lost"] = s.lost;
  j["fragments_lost_percent"] = s.lostPercent();
  j["culled"] = {
      {"occupancy", s.culledOccupancy}, {"kplus", s.culledKPlus}, {"in_store", s.rejectedInStore}};
  j["inserted"] = s.inserted;
  j["evicted"] = s.evicted;
  j["covered_pixels"] = s.coveredPixels;
  j["k_min"] = s.kMin;
  j["k_max"] = s.kMax;
  j["k"] = s.globalK ? nlohmann::json(*s.globalK) : nlohmann::json(nullptr);
  j["max_depth_complexity"] =
      s.maxDepthComplexity ? nlohmann::json(*s.maxDepthComplexity) : nlohmann::json(nullptr);
  j["mean_depth_complexity"] =
      s.meanDepthComplexity ? nlohmann::json(*s.meanDepthComplexity) : nlohmann::json(nullptr);
  nlohmann::json times = nlohmann::json::object();
  for (const PassTime& p : s.passes) times[p.name] = p.ms;
  j["time_ms"] = times;
  if (!s.engine.empty()) j["engine"] = s.engine;
  j["primitives_skipped"] = s.primitivesSkipped;
  j["cull"] = toString(s.cull);
  j["samples"] = s.samples;
  if (s.samples > 1) {
    j["sample_storage"] = toString(s.sampleStorage);
    j["edge_pixels"] = s.edgePixels;
    j["fragments_at_edges"] = s.fragmentsAtEdges;
    j["fragments_inside"] = s.fragmentsInside;
    j["lost_at_edges"] = s.lostAtEdges;
    j["lost_inside"] = s.lostInside;
  }
  if (!s.isa.empty()) j["isa"] = s.isa;
  for (const auto& [name, value] : s.engineCounters) j["engine_counters"][name] = value;
  j["total_ms"] = s.totalMs();
  if (s.peelPasses) j["peel_passes"] = *s.peelPasses;
  if (s.oracle) {
    const OracleReport& o = *s.oracle;
    j["oracle_error"] = o.error;
    j["oracle_lower_bound"] = o.lowerBound;
    j["oracle_gap"] = o.gap();
    j["oracle_lagrangian_bound"] = o.lagrangianBound;
    j["oracle_exact"] = o.exact;
    j["oracle_solver"] = o.solver;
    j["oracle_nonconvex_pixels"] = o.nonconvexPixels;
    j["oracle_core_pixels"] = o.corePixels;
  }
  return j;
}

}  // namespace mfr
