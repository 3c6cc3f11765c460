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

void RegionGrowingOptions::Check() const {
  Require(tile_size >= 8 && tile_size <= 4096,
          "mvs.growing.tile_size = ", tile_size, " must be in [8, 4096]");
  Require(revisit_margin >= 0 && revisit_margin <= 2,
          "mvs.growing.revisit_margin = ", revisit_margin,
          " must be in [0, 2] (NCC units)");
  Require(hypotheses >= 0 && hypotheses <= 16,
          "mvs.growing.hypotheses = ", hypotheses, " must be in [0, 16]");
  Require(start_views >= 0 && start_views <= kMaxNeighbors,
          "mvs.growing.start_views = ", start_views, " must be in [0, ",
          kMaxNeighbors, "]");
  Require(start_min_score >= -1 && start_min_score <= 1,
          "mvs.growing.start_min_score = ", start_min_score,
          " must be in [-1, 1]");
  Require(expand_min_ncc >= -1 && expand_min_ncc <= 1,
          "mvs.growing.expand_min_ncc = ", expand_min_ncc,
          " must be in [-1, 1]");
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
        opt_(options),
        matchers_(context, mpgc, local),
        W_(context.ref_image.width),
        H_(context.ref_image.height),
        T_(options.tile_size),
        ntx_((W_ + T_ - 1) / T_),
        nty_((H_ + T_ - 1) / T_),
        queues_(ntx_ * nty_),
        outbox_(ntx_ * nty_),
        visits_(ntx_ * nty_, 0),
        // Given in NCC units; confidence = (NCC + 1) / 2.
        margin_(static_cast<float>(0.5 * options.revisit_margin)),
        min_score_(mpgc.drop_ncc),
        expand_conf_(static_cast<float>(0.5 * (options.expand_min_ncc + 1))),
        // A held sample's explain verdict is not stored with the map: with
        // the explain test keeping unexplained matches, only held samples
        // above its gate (never tested) expand.
        held_expand_conf_(std::max(
            expand_conf_,
            mpgc.explain_margin >= 0 && mpgc.explain_keeps_match
                ? static_cast<float>(0.5 * (mpgc.explain_below_ncc + 1))
                : 0.0f)) {
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
        if (s.held) continue;  // expanded below, never matched
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
            !m->Match(seeds[i].x, seeds[i].y, seeds[i].depth,
                      seeds[i].normal.isZero() ? fronto : seeds[i].normal,
                      &res[i]))
          ok[i] = 0;
      }
      matchers_.Release(std::move(m));
    });
    stats_.pixel_visits += stats_.seeds_tried;
    // Held samples: their empty 4-neighbours are queued (seed order, so
    // deterministic), as GrowTile does after a match.
    {
      auto probe = matchers_.Acquire();
      for (const Seed& s : seeds) {
        if (!s.held || s.x < 0 || s.y < 0 || s.x >= W_ || s.y >= H_) continue;
        const int p = s.y * W_ + s.x;
        if (!(cmap_[p] > 0) || !(dmap_[p] > 0)) continue;
        if (cmap_[p] < held_expand_conf_) continue;
        ++stats_.held_seeds;
        const Eigen::Vector3d n(nmap_[3 * p], nmap_[3 * p + 1],
                                nmap_[3 * p + 2]);
        const Eigen::Vector3d X0 = cam_.BackprojectCam(
            Eigen::Vector2d(s.x + 0.5, s.y + 0.5), dmap_[p]);
        static const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
        for (int k = 0; k < 4; ++k) {
          const int nx = s.x + dx[k], ny = s.y + dy[k];
          if (nx < 0 || ny < 0 || nx >= W_ || ny >= H_) continue;
          const int np = ny * W_ + nx;
          if (!WorthVisit(np, cmap_[p])) continue;
          if (mmap_ && !mmap_[np]) continue;
          if (!probe->WindowInside(nx, ny)) continue;
          Candidate nc;
          nc.conf = cmap_[p];
          nc.pixel = np;
          nc.depth =
              static_cast<float>(PlaneDepthAt(cam_, nx, ny, X0, n, dmap_[p]));
          if (!(nc.depth > 0) || !std::isfinite(nc.depth)) continue;
          for (int j = 0; j < 3; ++j) nc.normal[j] = static_cast<float>(n[j]);
          Push(&queues_[TileOf(nx, ny)], nc);
        }
      }
      matchers_.Release(std::move(probe));
    }
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

  // The planes of (x, y)'s reconstructed 4-neighbours (order +x, -x, +y,
  // -y), each carried to (x, y): its depth there and its normal. With
  // `matched_only`, neighbours without a confidence (held seeds) are left
  // out. Returns how many (<= 4).
  int NeighbourPlanes(int x, int y, bool matched_only, double depth[4],
                      Eigen::Vector3d normal[4]) const {
    static const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
    int n = 0;
    for (int k = 0; k < 4; ++k) {
      const int nx = x + dx[k], ny = y + dy[k];
      if (nx < 0 || ny < 0 || nx >= W_ || ny >= H_) continue;
      const int q = ny * W_ + nx;
      if (!(dmap_[q] > 0) || (matched_only && !(cmap_[q] > 0))) continue;
      const Eigen::Vector3d nq(nmap_[3 * q], nmap_[3 * q + 1],
                               nmap_[3 * q + 2]);
      const Eigen::Vector3d Xq =
          cam_.BackprojectCam(Eigen::Vector2d(nx + 0.5, ny + 0.5), dmap_[q]);
      const double d = PlaneDepthAt(cam_, x, y, Xq, nq, dmap_[q]);
      if (!(d > 0) || !std::isfinite(d)) continue;
      depth[n] = d;
      normal[n++] = nq;
    }
    return n;
  }

  // Beyond the paper: when MPGC from the copied plane fails at (x, y), the
  // planes of p's reconstructed 4-neighbours and perturbations of the
  // copied plane are scored with the cheap NCC (no optimisation), and MPGC
  // runs again from the best `hypotheses` of them that score above kappa.
  bool MatchFromHypotheses(PatchMatcher* m, int x, int y, const Candidate& c,
                           PatchResult* r, long long* visits) {
    struct Hyp {
      double score;
      double depth;
      Eigen::Vector3d n;
    };
    Hyp hyps[16];
    int nh = 0;
    const Eigen::Vector3d cn(c.normal[0], c.normal[1], c.normal[2]);
    auto add = [&](double depth, const Eigen::Vector3d& n) {
      if (nh >= 16 || !(depth > 0) || !std::isfinite(depth)) return;
      const double score = m->PlaneScore(x, y, depth, n, 2);
      if (score > min_score_) hyps[nh++] = {score, depth, n};
    };
    double nd[4];
    Eigen::Vector3d nn[4];
    const int nnb = NeighbourPlanes(x, y, false, nd, nn);
    for (int i = 0; i < nnb; ++i) add(nd[i], nn[i]);
    // Perturbations: depth +-1 % and the normal tilted by 15 degrees about
    // the image axes (deterministic: no random numbers).
    for (double f : {0.99, 1.01}) add(c.depth * f, cn);
    const double a = 15 * M_PI / 180;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d axis =
          k < 2 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
      const Eigen::Vector3d n = Eigen::AngleAxisd(k % 2 ? a : -a, axis) * cn;
      if (n.z() < -0.2) add(c.depth, n);
    }
    std::sort(hyps, hyps + nh,
              [](const Hyp& u, const Hyp& v) { return u.score > v.score; });
    for (int i = 0; i < std::min(nh, opt_.hypotheses); ++i) {
      ++*visits;
      if (m->Match(x, y, hyps[i].depth, hyps[i].n, r)) return true;
    }
    return false;
  }

  // start_views: the start of the first MPGC at an empty pixel (x, y):
  // the candidate's copied plane or a reconstructed 4-neighbour's plane,
  // whichever scores best with the cheap NCC (ties: the copied plane, then
  // the neighbours in the order +x, -x, +y, -y). False (skip the pixel)
  // when the best scores below start_min_score.
  bool PickStart(PatchMatcher* m, int x, int y, const Candidate& c,
                 double* depth, Eigen::Vector3d* normal) {
    *depth = c.depth;
    *normal = Eigen::Vector3d(c.normal[0], c.normal[1], c.normal[2]);
    double nd[4], hd[4];
    Eigen::Vector3d nn[4], hn[4];
    int nh = 0;
    const int nnb = NeighbourPlanes(x, y, true, nd, nn);
    for (int i = 0; i < nnb; ++i) {
      // The plane the candidate was copied from (float-rounded): no new
      // hypothesis.
      if (std::abs(nd[i] - c.depth) <= 1e-5 * nd[i] &&
          nn[i].dot(*normal) > 1 - 1e-6)
        continue;
      hd[nh] = nd[i];
      hn[nh++] = nn[i];
    }
    if (nh == 0 && !(opt_.start_min_score > -1)) return true;
    double best = m->PlaneScore(x, y, *depth, *normal, 2, opt_.start_views);
    for (int i = 0; i < nh; ++i) {
      const double sc = m->PlaneScore(x, y, hd[i], hn[i], 2, opt_.start_views);
      if (sc > best) {
        best = sc;
        *depth = hd[i];
        *normal = hn[i];
      }
    }
    return !(opt_.start_min_score > -1) || best >= opt_.start_min_score;
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
      double start_depth = c.depth;
      Eigen::Vector3d start_normal(c.normal[0], c.normal[1], c.normal[2]);
      if (opt_.start_views > 0 && !(cmap_[p] > 0) &&
          !PickStart(m.get(), x, y, c, &start_depth, &start_normal))
        continue;
      if (!m->Match(x, y, start_depth, start_normal, &r) &&
          !(opt_.hypotheses > 0 && !(cmap_[p] > 0) &&
            MatchFromHypotheses(m.get(), x, y, c, &r, &visits_[tile])))
        continue;
      if (!(r.confidence > cmap_[p])) continue;
      const float conf = static_cast<float>(r.confidence);
      cmap_[p] = conf;
      dmap_[p] = static_cast<float>(r.depth);
      for (int k = 0; k < 3; ++k)
        nmap_[3 * p + k] = static_cast<float>(r.normal[k]);
      if (conf < expand_conf_ || !r.explained) continue;  // not expanded
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
  const RegionGrowingOptions& opt_;
  MatcherPool matchers_;
  const int W_, H_, T_, ntx_, nty_;
  std::vector<std::vector<Candidate>> queues_, outbox_;
  std::vector<long long> visits_;
  const float margin_;
  const double min_score_;
  const float expand_conf_;  // confidence below which a match does not expand
  const float held_expand_conf_;  // the same for held samples
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
    stats->held_seeds += st.held_seeds;
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
  registry
      ->Add(key("hypotheses"), &o->hypotheses,
            "when MPGC from the copied plane fails at an empty pixel, try "
            "this many alternative planes (neighbours', perturbed) ranked by "
            "NCC; 0 = paper")
      .Min(0)
      .Max(16);
  registry
      ->Add(key("start_views"), &o->start_views,
            "before the first MPGC at an empty pixel, start from the best of "
            "the copied plane and the 4-neighbours' planes by NCC over this "
            "many views (best global score); 0 = off (paper)")
      .Min(0)
      .Max(kMaxNeighbors);
  registry
      ->Add(key("start_min_score"), &o->start_min_score,
            "with start_views: skip the pixel when the best start's NCC (mean "
            "of the best 2) is below this; -1 = off")
      .Min(-1)
      .Max(1);
  registry
      ->Add(key("expand_min_ncc"), &o->expand_min_ncc,
            "a match whose mean NCC is below this is kept but does not "
            "queue its neighbours; -1 = every match expands (paper)")
      .Min(-1)
      .Max(1);
}

}  // namespace wild_mvs
