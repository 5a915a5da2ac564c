// Budgets from the scene (issue 48): before a run, what each method needs of a frame, counted on
// the frame's count pass with the functions that decide a render, not guessed:
//
//   minimum    the smallest budget M that allocate() (allocation.hpp) accepts with the engine's
//              memory model (Engine::memoryModel): the per-pixel and per-image words plus the
//              nodes the policy must give (one per pixel for fixed k, one per covered pixel for
//              the count-pass policies under kbuffer compositing, every fragment for the A-buffer,
//              none for the accumulators and, under hybrid compositing, for the per-pixel
//              policies); found by a binary search over M with allocate() itself, so any rule it
//              has is the rule here. A method the engine's pre-flight (Engine::preflight) or its
//              pass plan refuses at every budget has no minimum, and the refusal is its note.
//   exact at   the smallest budget at which the method keeps every fragment: its allocation gives
//              k(p) >= n(p) for every pixel (the linked list: a pool of N = sum n(p) nodes), so a
//              render loses none (RenderStats::lost = 0). Searched the same way with allocate() on
//              the count pass's n(p) (and, for vkb, the importance map render() computes: n(p),
//              the view's nearest |n.v|, the method's parameters). Absent where no budget makes
//              the method keep every fragment, with the reason in `note`: the accumulating
//              approximations (wboit, mboit*, aoit*, dfaoit, stochastic*, hashed-alpha) never
//              do; an explicit k below the largest n(p) never does; the deep k-buffer's paper
//              rule (dkb) reads F(M) as a network feature, so its k(p) at one budget says nothing
//              of another. Depth peeling keeps every fragment without --max-peels at its fixed
//              memory (passes, not bytes).
//   fixed      the bytes of a method whose memory does not depend on the budget: the accumulators
//              (no nodes), the A-buffer (every fragment), an explicit k under fixed or counted k.
//   A-buffer   the exact A-buffer's bytes, k(p) = n(p): the ground truth's memory (per sample when
//              multisampled, as compare's ground truth).
//
// autoBudgets turns the table into `compare --budget auto`'s list: log-spaced from the smallest
// minimum to the A-buffer's bytes or the largest minimum, whichever is larger.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "mfr/core/result.hpp"
#include "mfr/engine/engine.hpp"
#include "mfr/method/budget_spec.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/render_output.hpp"

namespace mfr {

/// What budgets mean to one method on one frame (see above).
struct MethodBudget {
  std::string method;                    // MethodDesc::name
  std::optional<uint64_t> minimumBytes;  // none: refused at every budget (see note)
  /// The smallest share of the A-buffer's node bytes (BudgetSpec::relative) that resolveBudget
  /// accepts (smallestWorkingPercent): 0 when any share works; none when the frame has no
  /// fragment and the method needs one.
  std::optional<double> minimumPercent;
  std::optional<uint64_t> exactBytes;  // none: no budget keeps every fragment (see note)
  std::optional<uint64_t> fixedBytes;  // set when the memory does not depend on the budget
  std::string note;                    // why a value is absent, or how it was found; may be empty
};

/// The budget table of one frame.
struct SceneBudgets {
  int width = 0, height = 0, samples = 1;
  /// n(p) of the count pass (Engine::countFragments: summed over the samples when multisampled):
  /// the fragments N a relative budget is a share of, and the covered pixels.
  FrameCounts counts;
  uint32_t maxDepthComplexity = 0;
  double meanDepthComplexity = 0.0;   // over the covered pixels
  uint64_t abufferBytes = 0;          // the exact A-buffer's memory, k(p) = n(p)
  std::vector<MethodBudget> methods;  // in the order given
};

/// The table for `methods` (as they will render: compositing, k, ... set on each MethodDesc) on
/// `view` with `options` (capture mode, sample storage, memory limit, previousNearestCosine;
/// budgetBytes is ignored). Errors (one line): the count pass's; a method's own refusal is its
/// row's note, not an error.
Result<SceneBudgets> sceneBudgets(Engine& engine, const PreparedView& view,
                                  const std::vector<MethodDesc>& methods,
                                  const RenderOptions& options);

/// One method's row of sceneBudgets.
Result<MethodBudget> methodBudget(Engine& engine, const PreparedView& view,
                                  const MethodDesc& method, const RenderOptions& options);

/// `compare --budget auto`: up to `count` (at least 2) absolute budgets, log-spaced from the
/// smallest minimum among the methods whose memory depends on the budget (of all of them when
/// none does) to the larger of the A-buffer's bytes and the largest minimum (so that every
/// method runs at the last budget: on a real scene the exact A-buffer is often smaller than the
/// accumulating methods' fixed memory), each
/// rounded up to a tidy size (a multiple of an eighth of its leading power of two, at least
/// 1 KiB), ascending and distinct. Empty when no method has a minimum.
std::vector<BudgetSpec> autoBudgets(const SceneBudgets& budgets, int count = 5);

/// The one-line refusal of a run of `row`'s method at `budgetLabel` below its minimum, naming it:
/// "fkb at 700KB: needs at least 3.00 MiB (3145728 B) at 512x512". `size` names the frame.
std::string belowMinimumText(const MethodBudget& row, const std::string& budgetLabel,
                             const std::string& size);

}  // namespace mfr
