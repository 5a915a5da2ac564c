#include "view_settings.hpp"

namespace mfr::view {

std::string ViewSettings::methodKey() const {
  const ImportanceParams& ip = importance;
  return method + "|" + composite + "|" + std::to_string(budgetBytes) + "|" + std::to_string(k) +
         "|" + std::to_string(occupancyD) + "|" + std::to_string(maxPeels) + "|" +
         std::to_string(ip.alpha) + "," + std::to_string(ip.nLimit) + "," +
         std::to_string(ip.peripheryExponent) + "," + std::to_string(ip.noise) + "," +
         std::to_string(ip.seed) + "," + std::to_string(ip.useDepth) +
         std::to_string(ip.usePeriphery) + std::to_string(ip.useFresnel) +
         std::to_string(ip.useNoise) + "," +
         (ip.fovea ? std::to_string(ip.fovea->x) + "," + std::to_string(ip.fovea->y) : "centre") +
         "|" + model + "|" + camera.spec();
}

std::string ViewSettings::displayKey() const {
  return methodKey() + "|" + viewModeName(mode) + "|" + std::to_string(wiper) +
         (compare ? "|compare" : "");
}

}  // namespace mfr::view
