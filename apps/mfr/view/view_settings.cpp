#include "view_settings.hpp"

namespace mfr::view {

std::string ViewSettings::methodKey() const {
  return method + "|" + composite + "|" + std::to_string(budgetBytes) + "|" + std::to_string(k) +
         "|" + camera.spec();
}

std::string ViewSettings::displayKey() const {
  return methodKey() + "|" + viewModeName(mode) + "|" + std::to_string(wiper) +
         (compare ? "|compare" : "");
}

}  // namespace mfr::view
