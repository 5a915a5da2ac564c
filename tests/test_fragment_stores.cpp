// The bounded per-pixel stores of the k-buffer family (k+-buffer paper sec. 3.2, Algorithm 2):
// property tests over random fragment streams against an independent reference (a plain sort of
// the stream by (depth, colour)), for the max-array and the max-heap, with and without the k+
// culling test in front of the insertion as the capture pipeline runs it.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "mfr/cpu/fragment_stores.hpp"

namespace mfr {
namespace {

constexpr uint32_t kCapacities[] = {1, 2, 3, 8, 16, 17, 32, 64};
constexpr int kSeeds = 40;

enum class Order { Random, Ascending, Descending };
const char* orderName(Order o) {
  return o == Order::Random ? "random" : o == Order::Ascending ? "ascending" : "descending";
}

// The order every store must realise, written out on (depth, colour) rather than on the packed
// 64-bit node: nearer first, equal depths broken by the colour word.
bool nearer(FragmentNode a, FragmentNode b) {
  return std::make_tuple(nodeDepth(a), nodeColor(a)) < std::make_tuple(nodeDepth(b), nodeColor(b));
}

std::vector<FragmentNode> sortedByDepthThenColor(std::vector<FragmentNode> v) {
  std::sort(v.begin(), v.end(), nearer);
  return v;
}

// A random fragment stream. The seed picks the flavour: continuous depths (with 0, a denormal and
// 1.0 mixed in), a handful of distinct depths (many ties broken by colour), or a handful of
// depths and colours (many nodes equal in depth and colour).
std::vector<FragmentNode> randomStream(uint32_t seed, uint32_t capacity, Order order) {
  std::mt19937 rng(seed * 7919u + capacity);
  const uint32_t length = std::uniform_int_distribution<uint32_t>(0, 3 * capacity + 8)(rng);
  const int flavour = static_cast<int>(seed % 3);
  const float special[] = {0.0f, std::numeric_limits<float>::denorm_min(), 1.0f,
                           std::nextafter(1.0f, 0.0f)};
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<FragmentNode> stream;
  for (uint32_t i = 0; i < length; ++i) {
    float depth;
    uint32_t rgba;
    if (flavour == 0) {
      depth = rng() % 8 == 0 ? special[rng() % 4] : unit(rng);
      rgba = static_cast<uint32_t>(rng());
    } else if (flavour == 1) {
      depth = 0.25f * static_cast<float>(rng() % 4);
      rgba = static_cast<uint32_t>(rng());
    } else {
      depth = 0.125f + 0.25f * static_cast<float>(rng() % 3);
      rgba = 0x80000000u | static_cast<uint32_t>(rng() % 3);
    }
    stream.push_back(makeNode(depth, rgba));
  }
  if (order == Order::Ascending) stream = sortedByDepthThenColor(stream);
  if (order == Order::Descending) {
    stream = sortedByDepthThenColor(stream);
    std::reverse(stream.begin(), stream.end());
  }
  return stream;
}

std::string label(StoreKind kind, uint32_t k, uint32_t seed, Order order, bool kplus) {
  std::string s = kind == StoreKind::MaxArray ? "max-array" : "max-heap";
  s += " k=";
  s += std::to_string(k);
  s += " seed=";
  s += std::to_string(seed);
  s += " order=";
  s += orderName(order);
  s += kplus ? " with k+ test" : " without k+ test";
  return s;
}

// Everything one run of a stream through a store leaves behind.
struct StoreRun {
  std::vector<FragmentNode> kept, evicted, rejected;
};

// Feeds the stream into a store of the given capacity and checks the invariants after every
// insertion: the counter, slot 0 holds the maximum, the heap property, the k nearest of the prefix
// so far, and that nothing is written outside the pixel's region.
void runStream(StoreKind kind, uint32_t capacity, const std::vector<FragmentNode>& stream,
               bool kplusTest, const std::string& what, StoreRun& run) {
  constexpr FragmentNode kCanary = 0xdeadbeefcafef00dull;
  std::vector<FragmentNode> region(capacity + 2, kCanary);
  FragmentNode* slots = region.data() + 1;
  uint32_t count = 0;
  run = {};
  std::vector<FragmentNode> prefix;
  for (const FragmentNode node : stream) {
    prefix.push_back(node);
    const uint32_t before = count;
    const FragmentNode maxBefore = before > 0 ? slots[0] : 0;
    if (kplusTest && !passesKPlusTest(slots, count, capacity, node)) {
      // the test only rejects what the store itself would reject
      EXPECT_EQ(count, capacity) << what;
      EXPECT_FALSE(nearer(node, slots[0])) << what;
      run.rejected.push_back(node);
    } else {
      FragmentNode evicted = 0;
      const InsertOutcome outcome = storeInsert(kind, slots, count, capacity, node, evicted);
      if (before < capacity) {
        EXPECT_EQ(outcome, InsertOutcome::Inserted) << what;
        EXPECT_EQ(count, before + 1) << what;
      } else if (nearer(node, maxBefore)) {
        EXPECT_EQ(outcome, InsertOutcome::Replaced) << what;
        EXPECT_EQ(evicted, maxBefore) << what << ": the evicted node is the previous maximum";
        run.evicted.push_back(evicted);
      } else {
        EXPECT_EQ(outcome, InsertOutcome::Rejected) << what;
        run.rejected.push_back(node);
      }
      EXPECT_EQ(count, std::min<uint32_t>(before + 1, capacity)) << what;
    }
    // slot 0 holds the maximum
    for (uint32_t i = 1; i < count; ++i)
      ASSERT_FALSE(nearer(slots[0], slots[i])) << what << ": slot " << i << " exceeds slot 0";
    // heap property: no child is farther than its parent
    if (kind == StoreKind::MaxHeap) {
      for (uint32_t i = 1; i < count; ++i)
        ASSERT_FALSE(nearer(slots[(i - 1) / 2], slots[i])) << what << ": heap order at " << i;
    }
    // the store holds the `count` nearest of the prefix
    std::vector<FragmentNode> expected = sortedByDepthThenColor(prefix);
    expected.resize(count);
    ASSERT_EQ(sortedByDepthThenColor({slots, slots + count}), expected)
        << what << " after " << prefix.size() << " nodes";
  }
  EXPECT_EQ(region.front(), kCanary) << what << ": write before the region";
  EXPECT_EQ(region.back(), kCanary) << what << ": write past the region";
  run.kept.assign(slots, slots + count);
}

TEST(FragmentNode, OrderIsDepthThenColor) {
  std::mt19937 rng(3);
  const float depths[] = {
      0.0f, std::numeric_limits<float>::denorm_min(), 1e-30f, 0.5f, std::nextafter(1.0f, 0.0f),
      1.0f};
  for (int i = 0; i < 2000; ++i) {
    const float da = depths[rng() % 6], db = depths[rng() % 6];
    const uint32_t ca = static_cast<uint32_t>(rng()),
                   cb = rng() % 2 ? ca : static_cast<uint32_t>(rng());
    const FragmentNode a = makeNode(da, ca), b = makeNode(db, cb);
    EXPECT_EQ(nodeDepth(a), da);
    EXPECT_EQ(nodeColor(a), ca);
    EXPECT_EQ(a < b, std::make_tuple(da, ca) < std::make_tuple(db, cb)) << da << " " << db;
  }
  EXPECT_TRUE(makeNode(1.0f, 0xffffffffu) < kFarNode);
}

// Runs every store kind, capacity, seed, arrival order and k+ setting over its random stream and
// hands the outcome to `check(k, stream, run, what)`; stops at the first fatal failure.
template <class Check>
void forEveryStreamCase(Check&& check) {
  for (const StoreKind kind : {StoreKind::MaxArray, StoreKind::MaxHeap})
    for (const uint32_t k : kCapacities)
      for (uint32_t seed = 0; seed < kSeeds; ++seed)
        for (const Order order : {Order::Random, Order::Ascending, Order::Descending})
          for (const bool kplus : {false, true}) {
            const std::vector<FragmentNode> stream = randomStream(seed, k, order);
            const std::string what = label(kind, k, seed, order, kplus);
            StoreRun run;
            runStream(kind, k, stream, kplus, what, run);
            if (::testing::Test::HasFatalFailure()) return;
            check(k, stream, run, what);
            if (::testing::Test::HasFatalFailure()) return;
          }
}

TEST(BoundedStores, KeepExactlyTheKNearestOfAnyStream) {
  forEveryStreamCase([](uint32_t k, const std::vector<FragmentNode>& stream, const StoreRun& run,
                        const std::string& what) {
    std::vector<FragmentNode> expected = stream;
    const size_t keep = std::min<size_t>(k, stream.size());
    std::partial_sort(expected.begin(), expected.begin() + keep, expected.end());
    expected.resize(keep);
    ASSERT_EQ(sortedByDepthThenColor(run.kept), expected) << what;
  });
}

TEST(BoundedStores, KeptEvictedAndRejectedNodesPartitionTheStream) {
  forEveryStreamCase([](uint32_t k, const std::vector<FragmentNode>& stream, const StoreRun& run,
                        const std::string& what) {
    std::vector<FragmentNode> all = run.kept;
    all.insert(all.end(), run.evicted.begin(), run.evicted.end());
    all.insert(all.end(), run.rejected.begin(), run.rejected.end());
    std::vector<FragmentNode> input = stream;
    std::sort(all.begin(), all.end());
    std::sort(input.begin(), input.end());
    ASSERT_EQ(all, input) << what;
    // nothing leaves a store that belongs to the k nearest
    const size_t keep = std::min<size_t>(k, stream.size());
    if (keep > 0) {
      const FragmentNode kth = input[keep - 1];
      for (const FragmentNode n : run.evicted) ASSERT_FALSE(nearer(n, kth)) << what;
      for (const FragmentNode n : run.rejected) ASSERT_FALSE(nearer(n, kth)) << what;
    }
  });
}

TEST(BoundedStores, DescendingStreamEvictsOnEveryInsertionOnceFull) {
  // the k+ test's worst case: every fragment is nearer than the current maximum, so nothing is
  // culled and every insertion into a full store evicts
  for (const StoreKind kind : {StoreKind::MaxArray, StoreKind::MaxHeap})
    for (const uint32_t k : kCapacities) {
      std::vector<FragmentNode> stream;
      for (uint32_t i = 0; i < 3 * k + 5; ++i)
        stream.push_back(makeNode(1.0f - static_cast<float>(i) / 1024.0f, i));
      StoreRun run;
      runStream(kind, k, stream, true, label(kind, k, 0, Order::Descending, true), run);
      EXPECT_TRUE(run.rejected.empty());
      EXPECT_EQ(run.evicted.size(), stream.size() - k);
      // evicted in stream order: each evicted node is the farthest remaining one
      EXPECT_EQ(run.evicted, std::vector<FragmentNode>(stream.begin(), stream.end() - k));
    }
}

TEST(BoundedStores, AscendingStreamIsCulledByTheKPlusTestOnceFull) {
  for (const StoreKind kind : {StoreKind::MaxArray, StoreKind::MaxHeap})
    for (const uint32_t k : kCapacities) {
      std::vector<FragmentNode> stream;
      for (uint32_t i = 0; i < 3 * k + 5; ++i)
        stream.push_back(makeNode(static_cast<float>(i) / 1024.0f, 0xff000000u));
      StoreRun run;
      runStream(kind, k, stream, true, label(kind, k, 0, Order::Ascending, true), run);
      EXPECT_TRUE(run.evicted.empty());
      EXPECT_EQ(run.rejected, std::vector<FragmentNode>(stream.begin() + k, stream.end()));
    }
}

TEST(BoundedStores, ArrayAndHeapCaptureTheSameSet) {
  for (const uint32_t k : kCapacities)
    for (uint32_t seed = 0; seed < kSeeds; ++seed)
      for (const Order order : {Order::Random, Order::Ascending, Order::Descending}) {
        const std::vector<FragmentNode> stream = randomStream(seed, k, order);
        std::vector<FragmentNode> array(k), heap(k);
        uint32_t arrayCount = 0, heapCount = 0;
        std::vector<FragmentNode> arrayOut, heapOut;  // evicted or rejected, in stream order
        for (const FragmentNode node : stream) {
          FragmentNode evicted = 0;
          InsertOutcome o = maxArrayInsert(array.data(), arrayCount, k, node, evicted);
          if (o != InsertOutcome::Inserted)
            arrayOut.push_back(o == InsertOutcome::Replaced ? evicted : node);
          o = maxHeapInsert(heap.data(), heapCount, k, node, evicted);
          if (o != InsertOutcome::Inserted)
            heapOut.push_back(o == InsertOutcome::Replaced ? evicted : node);
          ASSERT_EQ(arrayCount, heapCount);
          ASSERT_EQ(array[0], heap[0]) << "the maximum of the array and the heap agree";
        }
        array.resize(arrayCount);
        heap.resize(heapCount);
        std::sort(array.begin(), array.end());
        std::sort(heap.begin(), heap.end());
        EXPECT_EQ(array, heap) << "k=" << k << " seed=" << seed << " " << orderName(order);
        // the node leaving the store at each step is the farthest of the k+1 candidates, so the
        // two stores emit the same sequence
        EXPECT_EQ(arrayOut, heapOut) << "k=" << k << " seed=" << seed << " " << orderName(order);
      }
}

TEST(BoundedStores, AtomicAccessBehavesLikePlainAccess) {
  for (const StoreKind kind : {StoreKind::MaxArray, StoreKind::MaxHeap})
    for (const uint32_t k : {1u, 3u, 17u})
      for (uint32_t seed = 0; seed < 10; ++seed) {
        const std::vector<FragmentNode> stream = randomStream(seed, k, Order::Random);
        std::vector<FragmentNode> plain(k), atomic(k);
        uint32_t plainCount = 0, atomicCount = 0;
        for (const FragmentNode node : stream) {
          const bool passPlain = passesKPlusTest<PlainAccess>(plain.data(), plainCount, k, node);
          const bool passAtomic =
              passesKPlusTest<AtomicAccess>(atomic.data(), atomicCount, k, node);
          ASSERT_EQ(passPlain, passAtomic);
          FragmentNode e1 = 0, e2 = 0;
          ASSERT_EQ(storeInsert<PlainAccess>(kind, plain.data(), plainCount, k, node, e1),
                    storeInsert<AtomicAccess>(kind, atomic.data(), atomicCount, k, node, e2));
          ASSERT_EQ(e1, e2);
          ASSERT_EQ(plain, atomic);
          ASSERT_EQ(plainCount, atomicCount);
        }
      }
}

TEST(KPlusTest, PassesWhileNotFullAndThenOnlyStrictlyNearerThanTheMaximum) {
  std::vector<FragmentNode> slots(2);
  uint32_t count = 0;
  const FragmentNode far = makeNode(0.75f, 5), nearNode = makeNode(0.25f, 5);
  EXPECT_TRUE(passesKPlusTest(slots.data(), count, 2, far));
  FragmentNode evicted = 0;
  (void)maxArrayInsert(slots.data(), count, 2, far, evicted);
  (void)maxArrayInsert(slots.data(), count, 2, nearNode, evicted);
  EXPECT_EQ(slots[0], far);
  EXPECT_FALSE(passesKPlusTest(slots.data(), count, 2, far)) << "equal to the maximum is culled";
  EXPECT_FALSE(passesKPlusTest(slots.data(), count, 2, makeNode(0.75f, 6)));
  EXPECT_TRUE(passesKPlusTest(slots.data(), count, 2, makeNode(0.75f, 4)))
      << "equal depth, smaller colour word is nearer";
  EXPECT_TRUE(passesKPlusTest(slots.data(), count, 2, makeNode(0.5f, 0xffffffffu)));
  // the pipeline's early test before shading uses colour 0: it never culls a node the full test
  // would keep
  std::mt19937 rng(11);
  for (int i = 0; i < 1000; ++i) {
    const float depth = static_cast<float>(rng() % 5) * 0.25f;
    const FragmentNode full = makeNode(depth, static_cast<uint32_t>(rng()));
    if (!passesKPlusTest(slots.data(), count, 2, makeNode(depth, 0u))) {
      EXPECT_FALSE(passesKPlusTest(slots.data(), count, 2, full));
    }
  }
}

TEST(AppendStore, KeepsEveryNodeInArrivalOrder) {
  const std::vector<FragmentNode> stream = randomStream(5, 8, Order::Random);
  std::vector<FragmentNode> slots(stream.size());
  uint32_t count = 0;
  FragmentNode evicted = 0;
  for (const FragmentNode node : stream)
    EXPECT_EQ(storeInsert(StoreKind::Append, slots.data(), count, 0, node, evicted),
              InsertOutcome::Inserted);
  EXPECT_EQ(count, stream.size());
  EXPECT_EQ(slots, stream);
}

}  // namespace
}  // namespace mfr
