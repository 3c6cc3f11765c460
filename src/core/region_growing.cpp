// Copyright wild_mvs authors.
#include "wild_mvs/core/region_growing.h"

#include <time.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <mutex>
#include <thread>

#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace {
// Side of a growth tile in pixels (the parallel unit).
constexpr int kTileSize = 32;
}  // namespace

void RegionGrowingOptions::Check() const {
  Require(revisit_margin >= 0 && revisit_margin <= 2,
          "mvs.growing.revisit_margin = ", revisit_margin,
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

namespace {

// The state of one GrowRegions call: R's maps, the tiles with their queues
// and inboxes, and the matchers. Its methods are the paper's steps: seed,
// grow (per tile, best first), merge the hand-offs between tiles.
class RegionGrower {
 public:
  RegionGrower(const PatchContext& context, const MpgcOptions& mpgc,
               const LocalViewSelectionOptions& local,
               const RegionGrowingOptions& options, const cv::Mat& mask,
               cv::Mat* depth, cv::Mat* normal, cv::Mat* confidence,
               const std::atomic<bool>* cancel)
      : cancel_(cancel),
        cam_(context.ref_camera),
        matchers_(context, mpgc, local),
        W_(context.ref_image.width),
        H_(context.ref_image.height),
        T_(kTileSize),
        ntx_((W_ + T_ - 1) / T_),
        nty_((H_ + T_ - 1) / T_),
        queues_(ntx_ * nty_),
        outbox_(ntx_ * nty_),
        visits_(ntx_ * nty_, 0),
        // Given in NCC units; confidence = (NCC + 1) / 2.
        margin_(static_cast<float>(0.5 * options.revisit_margin)) {
    if (!mask.empty()) mask_ = mask.isContinuous() ? mask : mask.clone();
    mmap_ = mask_.empty() ? nullptr : mask_.ptr<uint8_t>();
    dmap_ = depth->ptr<float>();
    nmap_ = normal->ptr<float>();
    cmap_ = confidence->ptr<float>();
  }

  // Seeds: matched fronto-parallel, in parallel; successes fill the queues
  // in seed order.
  void SeedQueues(const std::vector<Seed>& seeds, ThreadPool* pool) {
    const Eigen::Vector3d fronto(0, 0, -1);
    std::vector<int> ok(seeds.size(), 0);
    std::vector<PatchResult> res(seeds.size());
    {
      auto probe = matchers_.Acquire();
      for (size_t i = 0; i < seeds.size(); ++i) {
        const Seed& s = seeds[i];
        if (s.x < 0 || s.y < 0 || s.x >= W_ || s.y >= H_) continue;
        if (mmap_ && !mmap_[s.y * W_ + s.x]) continue;
        if (!probe->WindowInside(s.x, s.y) || !(s.depth > 0)) continue;
        ok[i] = 1;
        ++stats_.seeds_tried;
      }
      matchers_.Release(std::move(probe));
    }
    const int chunk = 64;
    const int nchunks = static_cast<int>((seeds.size() + chunk - 1) / chunk);
    stats_.cpu_seconds += RunParallel(pool, nchunks, [&](int ci) {
      auto m = matchers_.Acquire();
      const size_t end =
          std::min(seeds.size(), static_cast<size_t>(ci + 1) * chunk);
      for (size_t i = static_cast<size_t>(ci) * chunk; i < end; ++i) {
        if (ok[i] &&
            !m->Match(seeds[i].x, seeds[i].y, seeds[i].depth, fronto, &res[i]))
          ok[i] = 0;
      }
      matchers_.Release(std::move(m));
    });
    stats_.pixel_visits += stats_.seeds_tried;
    for (size_t i = 0; i < seeds.size(); ++i) {
      if (!ok[i]) continue;
      ++stats_.seeds_accepted;
      const PatchResult& r = res[i];
      Candidate c;
      c.conf = static_cast<float>(r.confidence);
      c.pixel = seeds[i].y * W_ + seeds[i].x;
      c.depth = static_cast<float>(r.depth);
      for (int k = 0; k < 3; ++k) c.normal[k] = static_cast<float>(r.normal[k]);
      Push(&queues_[TileOf(seeds[i].x, seeds[i].y)], c);
    }
  }

  // Phases over the four tile colours until every queue is empty.
  void Grow(ThreadPool* pool) {
    for (;;) {
      if (Cancelled()) break;
      bool any = false;
      for (size_t t = 0; t < queues_.size() && !any; ++t)
        any = !queues_[t].empty();
      if (!any) break;
      for (int colour = 0; colour < 4; ++colour) {
        std::vector<int> active;
        for (int t = 0; t < ntx_ * nty_; ++t) {
          const int cx = t % ntx_, cy = t / ntx_;
          if ((cx % 2) + 2 * (cy % 2) == colour && !queues_[t].empty())
            active.push_back(t);
        }
        if (active.empty()) continue;
        ++stats_.phases;
        stats_.cpu_seconds += RunParallel(pool, static_cast<int>(active.size()),
                                          [&](int i) { GrowTile(active[i]); });
        MergeOutboxes(active);
      }
    }
    for (long long v : visits_) stats_.pixel_visits += v;
  }

  const GrowStats& stats() const { return stats_; }

 private:
  static void Push(std::vector<Candidate>* q, const Candidate& c) {
    q->push_back(c);
    std::push_heap(q->begin(), q->end(), Lower());
  }
  int TileOf(int x, int y) const { return (y / T_) * ntx_ + (x / T_); }

  // Whether a candidate of confidence conf may (re)visit pixel p: always
  // when p holds nothing, else only when it beats p's confidence by more
  // than the margin.
  bool WorthVisit(int p, float conf) const {
    const float have = cmap_[p];
    return !(have > 0) || (have < conf && conf - have > margin_);
  }

  // Best-first growth inside one tile: pop, match, store, push the four
  // neighbours with the same plane (those of other tiles to this tile's
  // outbox).
  void GrowTile(int tile) {
    auto m = matchers_.Acquire();
    const int tx0 = (tile % ntx_) * T_, ty0 = (tile / ntx_) * T_;
    const int tx1 = std::min(W_, tx0 + T_), ty1 = std::min(H_, ty0 + T_);
    auto& q = queues_[tile];
    auto& out = outbox_[tile];
    PatchResult r;
    int since_check = 0;
    while (!q.empty()) {
      if (++since_check == 64) {
        since_check = 0;
        if (Cancelled()) {
          q.clear();
          break;
        }
      }
      std::pop_heap(q.begin(), q.end(), Lower());
      const Candidate c = q.back();
      q.pop_back();
      const int p = c.pixel;
      if (!WorthVisit(p, c.conf)) continue;
      const int x = p % W_, y = p / W_;
      ++visits_[tile];
      const Eigen::Vector3d start_normal(c.normal[0], c.normal[1], c.normal[2]);
      if (!m->Match(x, y, c.depth, start_normal, &r)) continue;
      if (!(r.confidence > cmap_[p])) continue;
      const float conf = static_cast<float>(r.confidence);
      cmap_[p] = conf;
      dmap_[p] = static_cast<float>(r.depth);
      for (int k = 0; k < 3; ++k)
        nmap_[3 * p + k] = static_cast<float>(r.normal[k]);
      if (!r.explained) continue;  // not expanded
      const Eigen::Vector3d X0 =
          cam_.BackprojectCam(Eigen::Vector2d(x + 0.5, y + 0.5), r.depth);
      static const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
      for (int k = 0; k < 4; ++k) {
        const int nx = x + dx[k], ny = y + dy[k];
        if (nx < 0 || ny < 0 || nx >= W_ || ny >= H_) continue;
        const int np = ny * W_ + nx;
        if (!WorthVisit(np, conf)) continue;
        if (mmap_ && !mmap_[np]) continue;
        if (!m->WindowInside(nx, ny)) continue;
        Candidate nc;
        nc.conf = conf;
        nc.pixel = np;
        nc.depth = static_cast<float>(
            PlaneDepthAt(cam_, nx, ny, X0, r.normal, r.depth));
        for (int j = 0; j < 3; ++j)
          nc.normal[j] = static_cast<float>(r.normal[j]);
        if (nx >= tx0 && nx < tx1 && ny >= ty0 && ny < ty1) {
          Push(&q, nc);
        } else {
          out.push_back(nc);
        }
      }
    }
    matchers_.Release(std::move(m));
  }

  // Hands the candidates for other tiles over, in tile order
  // (deterministic).
  void MergeOutboxes(const std::vector<int>& tiles) {
    for (int t : tiles) {
      for (const Candidate& c : outbox_[t])
        Push(&queues_[TileOf(c.pixel % W_, c.pixel / W_)], c);
      outbox_[t].clear();
    }
  }

  bool Cancelled() const {
    return cancel_ && cancel_->load(std::memory_order_relaxed);
  }

  const std::atomic<bool>* cancel_;  // null = never
  const Camera& cam_;
  MatcherPool matchers_;
  const int W_, H_, T_, ntx_, nty_;
  std::vector<std::vector<Candidate>> queues_, outbox_;
  std::vector<long long> visits_;
  const float margin_;
  cv::Mat mask_;
  const uint8_t* mmap_ = nullptr;
  float* dmap_ = nullptr;
  float* nmap_ = nullptr;
  float* cmap_ = nullptr;
  GrowStats stats_;
};

}  // namespace

void GrowRegions(const PatchContext& context, const MpgcOptions& mpgc,
                 const LocalViewSelectionOptions& local,
                 const RegionGrowingOptions& options,
                 const std::vector<Seed>& seeds, const cv::Mat& mask,
                 ThreadPool* pool, cv::Mat* depth, cv::Mat* normal,
                 cv::Mat* confidence, GrowStats* stats,
                 const std::atomic<bool>* cancel) {
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
  RegionGrower grower(context, mpgc, local, options, mask, depth, normal,
                      confidence, cancel);
  grower.SeedQueues(seeds, pool);
  grower.Grow(pool);
  if (stats) {
    const GrowStats& st = grower.stats();
    stats->seeds_tried += st.seeds_tried;
    stats->seeds_accepted += st.seeds_accepted;
    stats->pixel_visits += st.pixel_visits;
    stats->phases += st.phases;
    stats->cpu_seconds += st.cpu_seconds;
  }
}

void RegisterOptions(OptionRegistry* registry, const std::string& prefix,
                     RegionGrowingOptions* o) {
  registry
      ->Add(OptionRegistry::Join(prefix, "revisit_margin"), &o->revisit_margin,
            "revisit a pixel only from a candidate whose mean NCC beats the "
            "stored one by more than this, NCC units (paper: 0)")
      .Min(0)
      .Max(2);
}

}  // namespace wild_mvs
