// The sections of the one-view comparison report (compareReportHtml, report_html.cpp) that live
// in their own files, and the small formatting helpers they share. Internal to src/compare.
#pragma once

#include <string>

#include "mfr/compare/compare.hpp"
#include "mfr/core/image.hpp"

namespace mfr::report {

std::string psnrText(double psnr);
std::string mib(uint64_t bytes);
/// "2.00 MiB (2 097 152 B)"; a relative budget also names its share
std::string budgetTitle(const CompareBudget& cb);
/// the magma colour bar as a CSS gradient
std::string magmaGradient();
/// an image linked to its file, with an optional caption (empty file: an empty cell)
std::string imageCell(const std::string& file, const Image8& image, const std::string& alt,
                      const std::string& caption);

/// "Recommendation" (report_recommend.cpp): per budget the verdict and the ranking, the methods
/// the budget does not move, and the error-vs-bytes and error-vs-time Pareto fronts.
std::string recommendationSection(const CompareResult& r, int section);

/// "Images" (report_images.cpp): per budget a wiper (a method over the ground truth), the grid
/// of images, FLIP maps, k-maps and importance maps, and each run's worst region beside the
/// ground truth's.
std::string imagesSection(const CompareResult& r, int section);

}  // namespace mfr::report
