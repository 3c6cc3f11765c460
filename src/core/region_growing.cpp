// Copyright wild_mvs authors.
#include "wild_mvs/core/region_growing.h"

#include <time.h>

#include <algorithm>
#include <atomic>
#include <memory>
#include <mutex>
#include <thread>

#include "wild_mvs/core/error.h"

namespace wild_mvs {

void RegionGrowingOptions::Check() const {
  Require(tile_size >= 8 && tile_size <= 4096,
          "growing.tile_size = ", tile_size, " must be in [8, 4096]");
  Require(revisit_margin >= 0 && revisit_margin <= 2,
          "growing.revisit_margin = ", revisit_margin,
          " must be in [0, 2] (NCC units)");
}

double ThreadCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + ts.tv_nsec * 1e-9;
}

double RunParallel(ThreadPool* pool, int n,
                   const std::function<void(int)>& body) {
  std::atomic<long long> ns{0};
  const std::thread::id caller = std::this_thread::get_id();
  auto timed = [&](int i) {
    if (std::this_thread::get_id() == caller) return body(i);
    const double t0 = ThreadCpuSeconds();
    body(i);
    ns += static_cast<long long>((ThreadCpuSeconds() - t0) * 1e9);
  };
  if (pool && n > 1) {
    pool->ParallelFor(n, timed);
  } else {
    for (int i = 0; i < n; ++i) timed(i);
  }
  return ns.load() * 1e-9;
}

namespace {

struct Candidate {
  float conf;
  int pixel;
  float depth;
  float normal[3];
};

// Max-heap order: higher confidence first, then lower pixel index, then
// lower depth: a total order, so pops are deterministic.
struct Lower {
  bool operator()(const Candidate& a, const Candidate& b) const {
    if (a.conf != b.conf) return a.conf < b.conf;
    if (a.pixel != b.pixel) return a.pixel > b.pixel;
    if (a.depth != b.depth) return a.depth > b.depth;
    if (a.normal[0] != b.normal[0]) return a.normal[0] > b.normal[0];
    if (a.normal[1] != b.normal[1]) return a.normal[1] > b.normal[1];
    return a.normal[2] > b.normal[2];
  }
};

// A pool of matchers: one per concurrently running body.
class MatcherPool {
 public:
  MatcherPool(const PatchContext& ctx, const MpgcOptions& mpgc,
              const LocalViewSelectionOptions& local)
      : ctx_(ctx), mpgc_(mpgc), local_(local) {}
  std::unique_ptr<PatchMatcher> Acquire() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (free_.empty())
      return std::make_unique<PatchMatcher>(ctx_, mpgc_, local_);
    auto m = std::move(free_.back());
    free_.pop_back();
    return m;
  }
  void Release(std::unique_ptr<PatchMatcher> m) {
    std::lock_guard<std::mutex> lock(mutex_);
    free_.push_back(std::move(m));
  }

 private:
  const PatchContext& ctx_;
  const MpgcOptions& mpgc_;
  const LocalViewSelectionOptions& local_;
  std::mutex mutex_;
  std::vector<std::unique_ptr<PatchMatcher>> free_;
};

}  // namespace

void GrowRegions(const PatchContext& context, const MpgcOptions& mpgc,
                 const LocalViewSelectionOptions& local,
                 const RegionGrowingOptions& options,
                 const std::vector<Seed>& seeds, const cv::Mat& mask,
                 ThreadPool* pool, cv::Mat* depth, cv::Mat* normal,
                 cv::Mat* confidence, GrowStats* stats) {
  options.Check();
  const int W = context.ref_image.width, H = context.ref_image.height;
  Require(depth && normal && confidence, "GrowRegions: null output");
  if (depth->empty()) *depth = cv::Mat::zeros(H, W, CV_32F);
  if (normal->empty()) *normal = cv::Mat::zeros(H, W, CV_32FC3);
  if (confidence->empty()) *confidence = cv::Mat::zeros(H, W, CV_32F);
  Require(depth->cols == W && depth->rows == H && depth->type() == CV_32F &&
              normal->cols == W && normal->rows == H &&
              normal->type() == CV_32FC3 && confidence->cols == W &&
              confidence->rows == H && confidence->type() == CV_32F &&
              depth->isContinuous() && normal->isContinuous() &&
              confidence->isContinuous(),
          "GrowRegions: output maps must be continuous ", W, "x", H,
          " CV_32F / CV_32FC3 / CV_32F");
  Require(mask.empty() ||
              (mask.cols == W && mask.rows == H && mask.type() == CV_8U),
          "GrowRegions: mask must be CV_8U ", W, "x", H);
  float* dmap = depth->ptr<float>();
  float* nmap = normal->ptr<float>();
  float* cmap = confidence->ptr<float>();
  cv::Mat mask_c;
  if (!mask.empty()) mask_c = mask.isContinuous() ? mask : mask.clone();
  const uint8_t* mmap = mask_c.empty() ? nullptr : mask_c.ptr<uint8_t>();

  MatcherPool matchers(context, mpgc, local);
  GrowStats st;

  const int T = options.tile_size;
  const int ntx = (W + T - 1) / T, nty = (H + T - 1) / T;
  const int ntiles = ntx * nty;
  auto tile_of = [&](int x, int y) { return (y / T) * ntx + (x / T); };
  std::vector<std::vector<Candidate>> queues(ntiles), outbox(ntiles);
  std::vector<long long> visits(ntiles, 0);

  // Seeds: matched fronto-parallel, in parallel; successes fill the queues
  // in seed order.
  const Eigen::Vector3d fronto(0, 0, -1);
  std::vector<int> seed_ok(seeds.size(), 0);
  std::vector<PatchResult> seed_res(seeds.size());
  {
    auto probe = matchers.Acquire();
    for (size_t i = 0; i < seeds.size(); ++i) {
      const Seed& s = seeds[i];
      if (s.x < 0 || s.y < 0 || s.x >= W || s.y >= H) continue;
      if (mmap && !mmap[s.y * W + s.x]) continue;
      if (!probe->WindowInside(s.x, s.y) || !(s.depth > 0)) continue;
      seed_ok[i] = 1;
      ++st.seeds_tried;
    }
    matchers.Release(std::move(probe));
  }
  const int chunk = 64;
  const int nchunks = static_cast<int>((seeds.size() + chunk - 1) / chunk);
  st.cpu_seconds += RunParallel(pool, nchunks, [&](int ci) {
    auto m = matchers.Acquire();
    const size_t end =
        std::min(seeds.size(), static_cast<size_t>(ci + 1) * chunk);
    for (size_t i = static_cast<size_t>(ci) * chunk; i < end; ++i) {
      if (!seed_ok[i]) continue;
      if (!m->Match(seeds[i].x, seeds[i].y, seeds[i].depth, fronto,
                    &seed_res[i]))
        seed_ok[i] = 0;
    }
    matchers.Release(std::move(m));
  });
  st.pixel_visits += st.seeds_tried;
  for (size_t i = 0; i < seeds.size(); ++i) {
    if (!seed_ok[i]) continue;
    ++st.seeds_accepted;
    const PatchResult& r = seed_res[i];
    Candidate c;
    c.conf = static_cast<float>(r.confidence);
    c.pixel = seeds[i].y * W + seeds[i].x;
    c.depth = static_cast<float>(r.depth);
    for (int k = 0; k < 3; ++k) c.normal[k] = static_cast<float>(r.normal[k]);
    auto& q = queues[tile_of(seeds[i].x, seeds[i].y)];
    q.push_back(c);
    std::push_heap(q.begin(), q.end(), Lower());
  }

  const Camera& cam = context.ref_camera;
  // Whether a candidate of confidence conf may (re)visit pixel p: always
  // when p holds nothing, else only when it beats p's confidence by more
  // than the margin (given in NCC units; confidence = (NCC + 1) / 2).
  const float margin = static_cast<float>(0.5 * options.revisit_margin);
  auto worth_visit = [&](int p, float conf) {
    const float have = cmap[p];
    return !(have > 0) || (have < conf && conf - have > margin);
  };
  auto process_tile = [&](int tile) {
    auto m = matchers.Acquire();
    const int tx0 = (tile % ntx) * T, ty0 = (tile / ntx) * T;
    const int tx1 = std::min(W, tx0 + T), ty1 = std::min(H, ty0 + T);
    auto& q = queues[tile];
    auto& out = outbox[tile];
    PatchResult r;
    while (!q.empty()) {
      std::pop_heap(q.begin(), q.end(), Lower());
      const Candidate c = q.back();
      q.pop_back();
      const int p = c.pixel;
      if (!worth_visit(p, c.conf)) continue;
      const int x = p % W, y = p / W;
      ++visits[tile];
      if (!m->Match(x, y, c.depth,
                    Eigen::Vector3d(c.normal[0], c.normal[1], c.normal[2]), &r))
        continue;
      if (!(r.confidence > cmap[p])) continue;
      const float conf = static_cast<float>(r.confidence);
      cmap[p] = conf;
      dmap[p] = static_cast<float>(r.depth);
      for (int k = 0; k < 3; ++k)
        nmap[3 * p + k] = static_cast<float>(r.normal[k]);
      const Eigen::Vector3d X0 =
          cam.BackprojectCam(Eigen::Vector2d(x + 0.5, y + 0.5), r.depth);
      static const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
      for (int k = 0; k < 4; ++k) {
        const int nx = x + dx[k], ny = y + dy[k];
        if (nx < 0 || ny < 0 || nx >= W || ny >= H) continue;
        const int np = ny * W + nx;
        if (!worth_visit(np, conf)) continue;
        if (mmap && !mmap[np]) continue;
        if (!m->WindowInside(nx, ny)) continue;
        Candidate nc;
        nc.conf = conf;
        nc.pixel = np;
        nc.depth = static_cast<float>(
            PlaneDepthAt(cam, nx, ny, X0, r.normal, r.depth));
        for (int j = 0; j < 3; ++j)
          nc.normal[j] = static_cast<float>(r.normal[j]);
        if (nx >= tx0 && nx < tx1 && ny >= ty0 && ny < ty1) {
          q.push_back(nc);
          std::push_heap(q.begin(), q.end(), Lower());
        } else {
          out.push_back(nc);
        }
      }
    }
    matchers.Release(std::move(m));
  };

  for (;;) {
    bool any = false;
    for (int t = 0; t < ntiles && !any; ++t) any = !queues[t].empty();
    if (!any) break;
    for (int colour = 0; colour < 4; ++colour) {
      std::vector<int> active;
      for (int t = 0; t < ntiles; ++t) {
        const int cx = t % ntx, cy = t / ntx;
        if ((cx % 2) + 2 * (cy % 2) == colour && !queues[t].empty())
          active.push_back(t);
      }
      if (active.empty()) continue;
      ++st.phases;
      st.cpu_seconds += RunParallel(pool, static_cast<int>(active.size()),
                                    [&](int i) { process_tile(active[i]); });
      // Merge the outboxes in tile order (deterministic).
      for (int t : active) {
        for (const Candidate& c : outbox[t]) {
          auto& q = queues[tile_of(c.pixel % W, c.pixel / W)];
          q.push_back(c);
          std::push_heap(q.begin(), q.end(), Lower());
        }
        outbox[t].clear();
      }
    }
  }
  for (long long v : visits) st.pixel_visits += v;
  if (stats) {
    stats->seeds_tried += st.seeds_tried;
    stats->seeds_accepted += st.seeds_accepted;
    stats->pixel_visits += st.pixel_visits;
    stats->phases += st.phases;
    stats->cpu_seconds += st.cpu_seconds;
  }
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     RegionGrowingOptions* o) {
  auto key = [&prefix](const char* name) {
    return OptionRegistry::Join(prefix, name);
  };
  registry
      ->Add(key("tile_size"), &o->tile_size,
            "region growing tile side in pixels (parallel unit)")
      .Min(8)
      .Max(4096);
  registry->Add(key("seeds_from_neighbors"), &o->seeds_from_neighbors,
                "also seed from the neighbours' features projected into R");
  registry
      ->Add(key("revisit_margin"), &o->revisit_margin,
            "revisit a pixel only from a candidate whose mean NCC beats the "
            "stored one by more than this, NCC units (paper: 0)")
      .Min(0)
      .Max(2);
}

}  // namespace wild_mvs
