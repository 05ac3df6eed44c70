#include "plan/bake_plan.h"

#include "bake/integrator.h"
#include "core/stopwatch.h"
#include "plan/error_sample.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace rsibr {
namespace {

IntegratorOptions options_of(const IntegratorSetting& s, std::uint64_t seed) {
  IntegratorOptions o;
  o.samples = std::max(1, s.samples);
  o.reference_width = s.reference_width;
  o.seed = seed;
  return o;
}

// The integrator of the pilot's guide: deterministic for a seed and cheap.
const IntegratorSetting kInterpolationIntegrator{"fis", 64, 0};

// The integrator that measures e_interp: FIS (deterministic for a seed: no noise to mistake for
// blend error), the cheapest of the pilot's FIS settings whose own error is at most a third of the
// planned budget (the most accurate when none is), FIS 64 when the pilot has none. Its own error is
// not the blend's (see the header), and what the subtraction in quadrature does not take out is
// then small beside the budget. A fixed FIS 64 fails under a sharp coat: its own error exceeds the
// blend's raw error, the subtraction leaves e_interp at 0 for the larger view sets, and the screen
// lets through candidates that every confirmation then finds over the budget.
IntegratorSetting interpolation_integrator(const std::vector<IntegratorPilot>& pilots, double budget) {
  const IntegratorPilot* cheapest = nullptr;
  const IntegratorPilot* most_accurate = nullptr;
  for (const IntegratorPilot& p : pilots) {
    if (p.setting.method != "fis") continue;
    if (!most_accurate || p.error < most_accurate->error) most_accurate = &p;
    if (p.error <= budget / 3 && (!cheapest || p.seconds_per_texel < cheapest->seconds_per_texel)) cheapest = &p;
  }
  if (cheapest) return cheapest->setting;
  if (most_accurate) return most_accurate->setting;
  return kInterpolationIntegrator;
}

std::string percent(double e) {
  std::ostringstream s;
  s.precision(e < 0.1 ? 2 : 3);
  s << 100.0 * e << "%";
  return s.str();
}

std::string setting_text(const BakeSetting& b) {
  return std::to_string(b.view_count) + " views x " + std::to_string(b.res) + "^2, " + b.integrator.label();
}

// The integrator pilot: the truth (the full reference quadrature) at the sample's texels, then each
// setting's error against it and its time per texel. Keeps the integrators it made.
struct Pilots {
  const EnvMap& env;
  std::map<std::string, std::unique_ptr<Integrator>> made;
  std::map<std::string, double> setup;
  std::vector<IntegratorPilot> integrators;
  std::vector<Vec3> truth;

  explicit Pilots(const EnvMap& environment) : env(environment) {}

  const Integrator& integrator(const std::string& method) {
    auto it = made.find(method);
    if (it == made.end()) {
      const auto t = std::chrono::steady_clock::now();
      auto integrator = make_integrator(method, env);
      setup[method] = seconds_since(t);
      it = made.emplace(method, std::move(integrator)).first;
    }
    return *it->second;
  }

  void measure(const Brdf& brdf, const ErrorSample& sample, const std::vector<IntegratorSetting>& settings,
               std::uint64_t seed, int timing_size) {
    const Integrator& reference = integrator("reference");
    double truth_seconds = 0;
    truth = direct_values(reference, brdf, options_of({"reference", 0, 0}, seed), sample, &truth_seconds);
    for (const IntegratorSetting& s : settings) {
      const Integrator& chosen = integrator(s.method);
      IntegratorPilot p;
      p.setting = s;
      p.setup_seconds = setup[s.method];
      double seconds = 0;
      std::vector<Vec3> values;
      if (s.method == "reference" && s.reference_width == 0) {
        values = truth;
        seconds = truth_seconds;
      } else {
        try {
          // Warm-up on one texel: an integrator may build what a setting needs on first use (the
          // reference's MIP level), which is setup, not the time per texel.
          IntegratorOptions one = options_of(s, seed);
          one.texel_mask = cv::Mat::zeros(sample.size(), sample.size(), CV_8UC1);
          one.texel_mask.at<unsigned char>(sample.texels(0)[0] / sample.size(), sample.texels(0)[0] % sample.size()) =
              1;
          chosen.radiance_map(brdf, sample.view(0), sample.frame(0), sample.size(), one);
          values = direct_values(chosen, brdf, options_of(s, seed), sample, &seconds);
        } catch (const std::invalid_argument&) {
          continue;  // a setting this BRDF cannot use (sh for anything but Lambert)
        }
      }
      const ErrorEstimate e = sample_error(sample, values, truth);
      p.error = e.value;
      p.error_sigma = e.sigma;
      p.seconds_per_texel = seconds / double(sample.count());
      // The pilot's texels are a few per view, so their time is mostly each map's per-call
      // overhead and rows the threads cannot share (4x a bake's per-texel time for MIS 64 on 2
      // cores). A bake integrates whole maps: one whole map, the largest of timing_size, its half
      // and its quarter whose predicted time is at most a quarter of a second, times that (repeated
      // to at least 25 ms: a shorter time is mostly the scheduler's), the fastest of three such
      // windows (a window where other processes took the cores is slower, never faster: without
      // the minimum, the candidates' order by predicted time followed the machine's load, and two
      // runs of one plan chose differently on a busy machine).
      int size = timing_size;
      while (size > 32 && p.seconds_per_texel * double(disc_texel_count(size)) > 0.25) size /= 2;
      if (p.seconds_per_texel * double(disc_texel_count(size)) <= 0.25) {
        double fastest = std::numeric_limits<double>::infinity();
        for (int window = 0; window < 3; ++window) {
          const auto t = std::chrono::steady_clock::now();
          long long texels = 0;
          do {
            chosen.radiance_map(brdf, sample.view(0), sample.frame(0), size, options_of(s, seed));
            texels += disc_texel_count(size);
          } while (seconds_since(t) < 0.025);
          fastest = std::min(fastest, seconds_since(t) / double(texels));
        }
        p.seconds_per_texel = fastest;
      }
      integrators.push_back(p);
    }
  }
};

// Throws std::invalid_argument for options no plan can use (a budget outside (0, 1), an empty
// candidate list, a margin outside (0, 1], a size under 2, a view set that cannot be named, sigmas <
// 0, negative confirmation views, a guide size neither 0 nor >= 2), in that order; returns the named
// view sets, in order.
std::vector<ViewSet> check_options(const BakePlanOptions& options) {
  if (!(options.max_error > 0 && options.max_error < 1))
    throw std::invalid_argument("plan: the error budget must lie in (0, 1) (a relative RMS, e.g. 0.02 for 2%), not " +
                                std::to_string(options.max_error));
  if (options.view_sets.empty() || options.sizes.empty() || options.integrators.empty())
    throw std::invalid_argument("plan: no view set, map size or integrator to choose from");
  if (!(options.margin > 0 && options.margin <= 1)) throw std::invalid_argument("plan: the margin must lie in (0, 1]");
  for (int r : options.sizes)
    if (r < 2) throw std::invalid_argument("plan: map sizes must be at least 2, not " + std::to_string(r));
  std::vector<ViewSet> view_sets;
  for (const std::string& name : options.view_sets) view_sets.push_back(ViewSet::named(name));

  if (!(options.sigmas >= 0)) throw std::invalid_argument("plan: the number of standard errors must be >= 0");
  if (options.confirm_views < 0)
    throw std::invalid_argument("plan: the confirmation's views must be >= 0 (0: the pilot's own)");
  if (options.confirm_max_views < 0) throw std::invalid_argument("plan: the confirmation's most views must be >= 0");
  if (options.guide_size != 0 && options.guide_size < 2)
    throw std::invalid_argument("plan: the guide's size must be 0 (no guide) or at least 2");
  return view_sets;
}

// `views` novel views x pilot_texels texels of pilot_size discs drawn from `seed`, guided by a cheap
// bake of the interpolation integrator (with the plan's seed) unless guide_size is 0.
ErrorSample plan_sample(Pilots& pilots, const Brdf& brdf, const BakePlanOptions& options, int views,
                        std::uint64_t seed) {
  if (options.guide_size > 0)
    return ErrorSample(views, options.pilot_texels, options.pilot_size, seed,
                       squared_radiance_guide(pilots.integrator(kInterpolationIntegrator.method), brdf,
                                              options_of(kInterpolationIntegrator, options.seed), options.guide_size));
  return ErrorSample(views, options.pilot_texels, options.pilot_size, seed);
}

// A candidate: its planned setting, the index of its view set and e_int + k s_int.
struct Candidate {
  PlannedSetting planned;
  std::size_t set;
  double integration_upper;  // e_int + k s_int
};

// The screen counts e_interp at half: the FIS maps' blend against FIS direct values carries FIS's
// own error pattern, which does not cancel between the two and is not the whole of what the
// subtraction in quadrature takes out (under hall with GGX gold the pilot's e_interp for 642 x
// 64^2 was 2.9% while the whole setting checked at 1.86%), and a pessimistic screen keeps the
// cheaper candidates from ever being measured.
constexpr double kInterpolationScreen = 0.5;
// The model screens, a measurement decides (see the header): a screened-in candidate is blended
// at the confirmation texels with its own integrator and taken when that error plus k sigma fits. The
// screen is optimistic: an unbiased integrator's (mis) error counts at a third, the most the
// blend's 3 sources x 4 taps can average its noise away, and e_interp at half (above).
constexpr double kMisScreen = 1.0 / 3.0;
// A confirmation stops (when it may) once its pooled error provably exceeds kStopAbove times the
// planned budget (BakePlanner::confirm).
constexpr double kStopAbove = 1.5;

// plan_bake in steps, with the state they share: the pilot (the constructor), the screen with its
// confirmations, the two fall-back measurements and the plan with its why (finish). Each step
// fills in plan_; e_interp, the confirmations' samples and the screen's factors are measured once
// and kept here.
class BakePlanner {
 public:
  // The pilot; view_sets are options.view_sets named (check_options).
  BakePlanner(const EnvMap& env, const Brdf& brdf, const BakePlanOptions& options, std::vector<ViewSet> view_sets);

  void screen_and_confirm();
  void measure_least_screened();
  void measure_least_bound();
  BakePlan finish();

 private:
  std::pair<const ErrorSample&, const std::vector<Vec3>&> confirmation(std::size_t j);
  bool may_extend(int pooled) const;
  double planned_budget(int pooled) const;
  ErrorEstimate interpolation_error(std::size_t set, int res);
  std::vector<Candidate> candidates() const;
  double screened_integration(const PlannedSetting& s) const;
  bool dominated(std::size_t set, int res, double allowance) const;
  std::optional<ErrorEstimate> reached_interpolation(const Candidate& c, double ie);
  void calibrate(const PlannedSetting& s, double m, double ie, double interp);
  std::optional<ErrorEstimate> confirm(Candidate& c, bool may_stop);
  std::string explain() const;

  // The confirmations' texels of one round, with the truth there (own: nullopt for the pilot's).
  struct ConfirmRound {
    std::optional<ErrorSample> own;
    std::vector<Vec3> truth;
  };

  const Brdf& brdf_;
  const BakePlanOptions& options_;
  const std::vector<ViewSet> view_sets_;
  const double budget_;  // margin * max_error: the planned budget at the first round's views
  const double k_;       // options.sigmas
  const std::chrono::steady_clock::time_point t_start_;
  BakePlan plan_;
  Pilots pilots_;
  const ErrorSample sample_;  // the pilot's texels
  const int first_round_views_;
  // The confirmations' work is bounded by max_confirmations candidates' worth of first-round views
  // (a confirmation stopped early counts the views it measured; its later rounds are not counted, so
  // that a decision started is finished).
  const long long views_allowed_;
  int confirmations_ = 0;
  long long views_measured_ = 0;
  std::vector<ConfirmRound> rounds_;
  // e_interp's cache: the interpolation integrator's direct values at the pilot's texels, its own
  // error there, and each (view set, size) pair measured.
  std::vector<Vec3> interpolation_direct_;
  double interpolation_own_ = 0;
  std::map<std::pair<std::size_t, int>, ErrorEstimate> interpolation_;
  std::vector<Candidate> candidates_;  // by predicted time; plan_.settings follows it
  // The screen's factors (calibrate).
  double interpolation_screen_ = kInterpolationScreen;
  double mis_screen_ = kMisScreen;
  bool calibrated_ = false, mis_calibrated_ = false;
};

// The pilot's texels, guided by a cheap bake of the interpolation integrator; the truth there and
// every integrator setting's error and time per texel. Throws std::invalid_argument when no setting
// can bake the BRDF.
BakePlanner::BakePlanner(const EnvMap& env, const Brdf& brdf, const BakePlanOptions& options,
                         std::vector<ViewSet> view_sets)
    : brdf_(brdf),
      options_(options),
      view_sets_(std::move(view_sets)),
      budget_(options.margin * options.max_error),
      k_(options.sigmas),
      t_start_(std::chrono::steady_clock::now()),
      pilots_(env),
      sample_(plan_sample(pilots_, brdf, options, options.pilot_views, options.seed)),
      first_round_views_(options.confirm_views > 0 ? options.confirm_views : options.pilot_views),
      views_allowed_((long long)options.max_confirmations * first_round_views_) {
  plan_.options = options;
  pilots_.measure(brdf, sample_, options.integrators, options.seed, options.pilot_size);
  plan_.integrators = pilots_.integrators;
  plan_.truth_texels = sample_.count();
  if (plan_.integrators.empty()) throw std::invalid_argument("plan: no integrator setting can bake this BRDF");
  plan_.interpolation_integrator = interpolation_integrator(plan_.integrators, budget_);
  candidates_ = candidates();
}

// The confirmations' texels, in rounds: round 0 is a sample of its own (confirm_views novel views,
// another seed, drawn the same way), the pilot's own when confirm_views is 0; round j >= 1 adds
// confirm_views 2^(j-1) fresh views, so that rounds 0..j pool confirm_views 2^j. Each is made, with
// the truth there, when first needed: a plan that measures no candidate does not pay for its truth.
// The references hold until the next call.
std::pair<const ErrorSample&, const std::vector<Vec3>&> BakePlanner::confirmation(std::size_t j) {
  while (rounds_.size() <= j) {
    ConfirmRound r;
    if (options_.confirm_views > 0) {
      const std::size_t n = rounds_.size();
      const int views = n == 0 ? options_.confirm_views : options_.confirm_views << (n - 1);
      const std::uint64_t confirm_seed = (options_.seed ^ 0x9e3779b97f4a7c15ull) + n;
      r.own.emplace(plan_sample(pilots_, brdf_, options_, views, confirm_seed));
      r.truth =
          direct_values(pilots_.integrator("reference"), brdf_, options_of({"reference", 0, 0}, options_.seed), *r.own);
      plan_.truth_texels += r.own->count();
    }
    rounds_.push_back(std::move(r));
  }
  if (j == 0) plan_.confirm_texels = rounds_[0].own ? rounds_[0].own->count() : sample_.count();
  if (rounds_[j].own) return {*rounds_[j].own, rounds_[j].truth};
  return {sample_, pilots_.truth};
}

// Rounds beyond the first: only with a sample of the confirmations' own, up to confirm_max_views.
bool BakePlanner::may_extend(int pooled) const {
  return options_.confirm_views > 0 && 2 * pooled <= options_.confirm_max_views;
}

// The planned budget at n pooled views: the reserve (1 - margin) of the budget is for the
// confirmation's scatter between samples, which falls as 1 / sqrt(n); it is the whole reserve at
// the first round's views.
double BakePlanner::planned_budget(int pooled) const {
  const double reserve = options_.max_error - budget_;
  return options_.max_error - reserve * std::sqrt(double(first_round_views_) / std::max(pooled, first_round_views_));
}

// e_interp(N, r) with its standard error, measured when first needed: the FIS maps' blend against
// FIS direct values, less (in quadrature) FIS's own error against the truth at the same texels,
// which the direct side carries and the blend does not share. Each measurement is added to
// plan_.interpolation.
ErrorEstimate BakePlanner::interpolation_error(std::size_t set, int res) {
  const auto key = std::make_pair(set, res);
  if (auto it = interpolation_.find(key); it != interpolation_.end()) return it->second;
  const Integrator& integrator = pilots_.integrator(plan_.interpolation_integrator.method);
  const IntegratorOptions o = options_of(plan_.interpolation_integrator, options_.seed);
  if (interpolation_direct_.empty()) {
    interpolation_direct_ = direct_values(integrator, brdf_, o, sample_);
    interpolation_own_ = sample_error(sample_, interpolation_direct_, pilots_.truth).value;
    plan_.interpolation_integrator_error = interpolation_own_;
  }
  const SampledBlend b = sampled_blend(integrator, brdf_, o, view_sets_[set], res, options_.normalise_albedo, sample_);
  InterpolationPilot p;
  p.views = options_.view_sets[set];
  p.view_count = int(view_sets_[set].views().size());
  p.res = res;
  ErrorEstimate e = sample_error(sample_, b.values, interpolation_direct_, &b.weights);
  p.raw_error = e.value;
  e.value = std::sqrt(std::max(0.0, e.value * e.value - interpolation_own_ * interpolation_own_));
  p.error = e.value;
  p.error_sigma = e.sigma;
  p.texels = b.texels_baked;
  p.seconds = b.seconds;
  plan_.interpolation.push_back(p);
  interpolation_[key] = e;
  return e;
}

// Every candidate with its predicted time, cheapest first (a stable sort: ties keep the order view
// set, size, integrator).
std::vector<Candidate> BakePlanner::candidates() const {
  std::vector<Candidate> candidates;
  for (std::size_t v = 0; v < view_sets_.size(); ++v)
    for (int r : options_.sizes)
      for (const IntegratorPilot& p : plan_.integrators) {
        PlannedSetting s;
        s.setting = {options_.view_sets[v], int(view_sets_[v].views().size()), r, p.setting};
        s.integration_error = p.error;
        s.error = p.error;
        s.upper_error = p.error + k_ * p.error_sigma;
        s.seconds = p.setup_seconds + double(s.setting.view_count) * double(disc_texel_count(r)) * p.seconds_per_texel;
        candidates.push_back({s, v, s.upper_error});
      }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.planned.seconds < b.planned.seconds; });
  return candidates;
}

// The integration part of the screen: mis's error times its factor, any other's as measured.
double BakePlanner::screened_integration(const PlannedSetting& s) const {
  return s.setting.integrator.method == "mis" ? mis_screen_ * s.integration_error : s.integration_error;
}

// A pair (N, r) cannot meet an allowance that a measured pair with at least as many views and at
// least the size already misses (more views and texels do not interpolate worse): not measured.
bool BakePlanner::dominated(std::size_t set, int res, double allowance) const {
  for (const auto& [key, e] : interpolation_)
    if (view_sets_[key.first].views().size() >= view_sets_[set].views().size() && key.second >= res &&
        interpolation_screen_ * e.value > allowance)
      return true;
  return false;
}

// e_interp for c's pair when the screen reaches it (every pair when asked; else before a choice,
// when the screened integration part ie fits the budget and no measured pair dominates it), else
// the one already measured for the pair; nullopt when neither.
std::optional<ErrorEstimate> BakePlanner::reached_interpolation(const Candidate& c, double ie) {
  const int res = c.planned.setting.res;
  const double allowance = ie < budget_ ? std::sqrt(budget_ * budget_ - ie * ie) : 0.0;
  if (options_.every_pair || (!plan_.chosen && ie <= budget_ && !dominated(c.set, res, allowance)))
    return interpolation_error(c.set, res);
  if (auto it = interpolation_.find({c.set, res}); it != interpolation_.end()) return it->second;
  return std::nullopt;
}

// The screen, calibrated by what the measurements say. Each factor starts as above and becomes
// the least that the measurements so far imply, from measured^2 = (a e_interp)^2 + (b e_int)^2:
// the interpolation factor a from the measurements whose screened interpolation part is at least
// their integration part, mis's factor b from mis measurements whose integration part is the
// larger (elsewhere the factor is ill-determined). The screen stays as optimistic as the most
// favourable candidate measured, but it no longer spends the confirmations on candidates that
// every measurement so far says will miss (under a low sun the implied a was about 1 for every
// method, and 32 confirmations at half ran out before the candidates that could pass).
// m is s's measured error (or its lower bound), ie its screened integration part, interp its
// e_interp.
void BakePlanner::calibrate(const PlannedSetting& s, double m, double ie, double interp) {
  const double ip = interpolation_screen_ * interp;
  if (ip >= ie && interp > 0) {
    const double a = std::sqrt(std::max(0.0, m * m - ie * ie)) / interp;
    interpolation_screen_ = calibrated_ ? std::min(interpolation_screen_, a) : a;
    calibrated_ = true;
  } else if (s.setting.integrator.method == "mis" && s.integration_error > 0) {
    const double b = std::sqrt(std::max(0.0, m * m - ip * ip)) / s.integration_error;
    mis_screen_ = mis_calibrated_ ? std::min(mis_screen_, b) : b;
    mis_calibrated_ = true;
  }
}

// A candidate's measurement: its set's blend at the confirmation texels with its own integrator,
// round by round (below), each round an eighth of its views at a time, stopped (unless it may not
// stop) once the pooled error provably exceeds kStopAbove times the planned budget: then it misses
// whatever its standard error, its lower bound is kept, and nullopt is returned. Not at the budget
// itself: a bound just above the budget would tell the screen's calibration nothing, and a near
// miss is most of a measurement's cost anyway.
// The rounds, a sequential test on the pooled estimate e +- s over n views:
//   e + k s <= planned_budget(n): taken, once at least two rounds agree (the first round's views are
//     the ones every candidate was screened and selected at: the cheapest candidate they pass is
//     the one they favour most, and fresh views take that selection's luck out);
//   e - s > planned_budget(n): a miss (one standard error over);
//   else undecided: a further round doubles n, up to confirm_max_views; undecided there is a miss.
// A near miss on a flat error curve is decided by more views, not by a step up the grid, and a
// low draw of a heavy-tailed estimate meets fresh views before it is taken.
// Fills in c.planned's measured fields and meets.
std::optional<ErrorEstimate> BakePlanner::confirm(Candidate& c, bool may_stop) {
  PlannedSetting& s = c.planned;
  ErrorSums pooled;
  for (std::size_t j = 0;; ++j) {
    const auto [confirm_sample, confirm_values_truth] = confirmation(j);
    BlendErrorOptions stop;
    if (may_stop && options_.stop_early) {
      stop.stop_above = kStopAbove * budget_;
      stop.step = std::max(1, std::min(confirm_sample.view_count(), first_round_views_) / 8);
    } else {
      stop.step = confirm_sample.view_count();
    }
    const BlendErrorMeasure m =
        sampled_blend_error(pilots_.integrator(s.setting.integrator.method), brdf_,
                            options_of(s.setting.integrator, options_.seed), view_sets_[c.set], s.setting.res,
                            options_.normalise_albedo, confirm_sample, confirm_values_truth, stop, pooled);
    plan_.confirm_seconds += m.seconds;
    if (j == 0) views_measured_ += m.views;  // a decision started is finished
    s.measured_views = pooled.views() + m.views;
    if (!m.error) {
      s.measured_error.reset();
      s.measured_sigma.reset();
      s.measured_at_least = m.at_least;
      s.upper_error = m.at_least;
      s.meets = false;
      return std::nullopt;
    }
    pooled = m.sums;
    const ErrorEstimate e = *m.error;
    s.measured_at_least.reset();
    s.measured_error = e.value;
    s.measured_sigma = e.sigma;
    s.upper_error = e.upper(k_);
    const double planned = planned_budget(pooled.views());
    s.meets = s.upper_error <= planned;
    const bool extend = may_extend(pooled.views());
    if (s.meets && (j > 0 || !extend)) return e;
    if (e.value - e.sigma > planned || !extend) {
      s.meets = false;
      return e;
    }
  }
}

// The candidates in order of predicted time, each screened by the model (once e_interp for its pair
// is known) and, before a choice and within the confirmations' allowance, measured when the screen
// lets it through; the first that meets the budget is chosen. Every candidate is added to
// plan_.settings.
void BakePlanner::screen_and_confirm() {
  for (Candidate& c : candidates_) {
    PlannedSetting& s = c.planned;
    const double ie = screened_integration(s);
    const std::optional<ErrorEstimate> interp = reached_interpolation(c, ie);
    if (interp) {
      s.interpolation_error = interp->value;
      s.error = std::hypot(interp->value, s.integration_error);
      s.upper_error = std::hypot(interp->upper(k_), c.integration_upper);
      const double screened = std::hypot(interpolation_screen_ * interp->value, ie);
      if (!plan_.chosen) {
        s.screened_error = screened;
        s.interpolation_screen = interpolation_screen_;
        s.mis_screen = mis_screen_;
      }
      if (!plan_.chosen && screened <= budget_ && views_measured_ < views_allowed_) {
        ++confirmations_;
        // A confirmation stopped early calibrates with its lower bound: the factor it implies is a
        // lower bound of the one its whole measurement would, and the screen stays optimistic.
        const std::optional<ErrorEstimate> measured = confirm(c, true);
        calibrate(s, measured ? measured->value : *s.measured_at_least, ie, interp->value);
      }
    }
    if (s.meets && !plan_.chosen) plan_.chosen = s;
    plan_.settings.push_back(s);
  }
}

// When the screen let nothing through but its least screened candidate is within twice the plan,
// that one is measured, so that the plan can name the closest setting and the error it reaches
// (a near-mirror coat under a small bright lamp is screened out everywhere, and the plan would
// have nothing to name). Taken if it meets the budget after all. The full reference is left out:
// its measurement integrates the full quadrature at every texel the blend reads (minutes), for a
// setting that would bake for days, and the most accurate sampled integrator on the same set
// screens within a hair of it.
void BakePlanner::measure_least_screened() {
  if (plan_.chosen || confirmations_ != 0 || views_allowed_ <= 0) return;
  Candidate* least = nullptr;
  for (Candidate& c : candidates_) {
    const PlannedSetting& s = c.planned;
    const bool full_reference = s.setting.integrator.method == "reference" && s.setting.integrator.reference_width == 0;
    if (!full_reference && s.screened_error && *s.screened_error <= 2 * budget_ &&
        (!least || *s.screened_error < *least->planned.screened_error))
      least = &c;
  }
  if (!least) return;
  ++confirmations_;
  confirm(*least, false);
  plan_.settings[std::size_t(least - candidates_.data())] = least->planned;  // settings follow candidates
  if (least->planned.meets) plan_.chosen = least->planned;
}

// Without a choice, the plan names the closest setting with its error: when every confirmation
// stopped early, the one stopped at the least bound is measured at every view.
void BakePlanner::measure_least_bound() {
  if (plan_.chosen) return;
  for (const Candidate& c : candidates_)
    if (c.planned.measured_error) return;
  Candidate* least = nullptr;
  for (Candidate& c : candidates_)
    if (c.planned.measured_at_least && (!least || *c.planned.measured_at_least < *least->planned.measured_at_least))
      least = &c;
  if (!least) return;
  confirm(*least, false);
  plan_.settings[std::size_t(least - candidates_.data())] = least->planned;
}

// The plan: its time, the closest measured setting when none was chosen, and why.
BakePlan BakePlanner::finish() {
  plan_.pilot_seconds = seconds_since(t_start_);
  if (!plan_.chosen)
    for (const PlannedSetting& s : plan_.settings)
      if (s.measured_error && (!plan_.closest || s.upper_error < plan_.closest->upper_error)) plan_.closest = s;
  plan_.why = explain();
  return std::move(plan_);
}

// A cheaper candidate's line of the why: what was measured or modelled for it, and its time.
void explain_miss(std::ostream& why, const PlannedSetting& s) {
  why << "cheaper, misses: " << setting_text(s.setting) << ": ";
  if (s.measured_error)
    why << "measured " << percent(*s.measured_error) << " +- " << percent(*s.measured_sigma) << " at "
        << s.measured_views << " views (modelled " << percent(s.error) << ")";
  else if (s.measured_at_least)
    why << "measured over " << percent(*s.measured_at_least) << " (stopped early; modelled " << percent(s.error) << ")";
  else if (s.interpolation_error)
    why << "modelled " << percent(s.error) << ", at most " << percent(s.upper_error) << " (interpolation "
        << percent(*s.interpolation_error) << ", integration " << percent(s.integration_error) << ")";
  else
    why << "integration alone " << percent(s.integration_error) << ", at most " << percent(s.upper_error);
  why << ", " << s.seconds << " s\n";
}

// Why, in a few lines: the choice with its measurement, or that there is none with the closest
// setting; then up to three cheaper candidates and why they miss.
std::string BakePlanner::explain() const {
  std::ostringstream why;
  if (plan_.chosen) {
    const PlannedSetting& c = *plan_.chosen;
    why << "chosen: " << setting_text(c.setting) << ": measured " << percent(*c.measured_error) << " +- "
        << percent(*c.measured_sigma) << " at " << c.measured_views << " confirmation views (at most "
        << percent(c.upper_error) << " with " << k_ << " standard errors; modelled " << percent(c.error)
        << ": interpolation " << percent(*c.interpolation_error) << ", integration " << percent(c.integration_error)
        << "), " << c.seconds << " s; the budget is " << percent(options_.max_error) << ", planned to "
        << percent(planned_budget(c.measured_views)) << " at its " << c.measured_views << " views.\n";
  } else {
    why << "no setting is predicted to meet " << percent(options_.max_error) << " (planned to " << percent(budget_)
        << " at " << first_round_views_ << " views";
    if (may_extend(first_round_views_))
      why << ", to " << percent(planned_budget(options_.confirm_max_views)) << " at " << options_.confirm_max_views;
    why << "); the most accurate measured ones are listed in the table";
    if (views_measured_ >= views_allowed_)
      why << " (the plan stopped after measuring " << confirmations_
          << " candidates that the model let through, its allowance of confirmation views)";
    why << ".\n";
    if (plan_.closest) {
      const PlannedSetting& c = *plan_.closest;
      why << "closest: " << setting_text(c.setting) << ": measured " << percent(*c.measured_error) << " +- "
          << percent(*c.measured_sigma) << " at " << c.measured_views << " views (at most " << percent(c.upper_error)
          << "), " << c.seconds << " s; it is planned to meet a budget of "
          << percent(c.upper_error / (planned_budget(c.measured_views) / options_.max_error)) << ".\n";
    }
  }
  int shown = 0;
  for (const PlannedSetting& s : plan_.settings) {
    if (plan_.chosen && s.seconds >= plan_.chosen->seconds) break;
    if (shown++ == 3) break;
    explain_miss(why, s);
  }
  return why.str();
}

}  // namespace

std::string IntegratorSetting::label() const {
  if (method == "reference")
    return reference_width > 0 ? "reference width " + std::to_string(reference_width) : "reference (full)";
  if (method == "sh") return "sh order 2";
  return method + " " + std::to_string(samples) + " samples";
}

std::vector<IntegratorSetting> default_integrator_settings() {
  std::vector<IntegratorSetting> s;
  for (int w : {32, 64, 128, 256}) s.push_back({"reference", 0, w});
  s.push_back({"reference", 0, 0});
  for (int n : {16, 32, 64, 128, 256, 512, 1024}) s.push_back({"mis", n, 0});
  for (int n : {8, 16, 32, 64, 128, 256, 512}) s.push_back({"fis", n, 0});
  s.push_back({"sh", 0, 0});
  return s;
}

const PlannedSetting* setting_to_bake(const BakePlan& plan, bool* fallback) {
  if (fallback) *fallback = false;
  if (plan.chosen) return &*plan.chosen;
  const auto& c = plan.closest;
  if (!c || !c->measured_error || !(*c->measured_error <= plan.options.max_error)) return nullptr;
  if (fallback) *fallback = true;
  return &*c;
}

BakePlan plan_bake(const EnvMap& env, const Brdf& brdf, const BakePlanOptions& options) {
  BakePlanner planner(env, brdf, options, check_options(options));  // the pilot
  planner.screen_and_confirm();
  planner.measure_least_screened();
  planner.measure_least_bound();
  return planner.finish();
}

nlohmann::json BakePlan::to_json() const {
  auto setting_json = [](const BakeSetting& b) {
    return nlohmann::json{{"views", b.views},
                          {"view_count", b.view_count},
                          {"res", b.res},
                          {"method", b.integrator.method},
                          {"samples", b.integrator.samples},
                          {"reference_width", b.integrator.reference_width},
                          {"integrator", b.integrator.label()}};
  };
  auto planned_json = [&](const PlannedSetting& s) {
    nlohmann::json j = setting_json(s.setting);
    j["predicted_error"] = s.error;
    j["upper_error"] = s.upper_error;
    j["measured_error"] = s.measured_error ? nlohmann::json(*s.measured_error) : nlohmann::json();
    j["measured_sigma"] = s.measured_sigma ? nlohmann::json(*s.measured_sigma) : nlohmann::json();
    j["measured_at_least"] = s.measured_at_least ? nlohmann::json(*s.measured_at_least) : nlohmann::json();
    j["measured_views"] = s.measured_views;
    j["integration_error"] = s.integration_error;
    j["interpolation_error"] = s.interpolation_error ? nlohmann::json(*s.interpolation_error) : nlohmann::json();
    j["predicted_seconds"] = s.seconds;
    j["screened_error"] = s.screened_error ? nlohmann::json(*s.screened_error) : nlohmann::json();
    j["interpolation_screen"] = s.screened_error ? nlohmann::json(s.interpolation_screen) : nlohmann::json();
    j["mis_screen"] = s.screened_error ? nlohmann::json(s.mis_screen) : nlohmann::json();
    j["meets"] = s.meets;
    return j;
  };
  nlohmann::json j;
  j["max_error"] = options.max_error;
  j["margin"] = options.margin;
  j["sigmas"] = options.sigmas;
  j["pilot"] = {{"views", options.pilot_views},
                {"texels_per_view", options.pilot_texels},
                {"size", options.pilot_size},
                {"seed", options.seed},
                {"guide_size", options.guide_size},
                {"seconds", pilot_seconds},
                {"confirm_seconds", confirm_seconds},
                {"truth_texels", truth_texels},
                {"confirm_views", options.confirm_views},
                {"confirm_max_views", options.confirm_max_views},
                {"confirm_texels", confirm_texels}};
  j["integrators"] = nlohmann::json::array();
  for (const IntegratorPilot& p : integrators)
    j["integrators"].push_back({{"integrator", p.setting.label()},
                                {"error", p.error},
                                {"error_sigma", p.error_sigma},
                                {"seconds_per_texel", p.seconds_per_texel},
                                {"setup_seconds", p.setup_seconds}});
  j["interpolation_integrator"] = interpolation_integrator.label();
  j["interpolation_integrator_error"] = interpolation_integrator_error;
  j["interpolation"] = nlohmann::json::array();
  for (const InterpolationPilot& p : interpolation)
    j["interpolation"].push_back({{"views", p.views},
                                  {"view_count", p.view_count},
                                  {"res", p.res},
                                  {"error", p.error},
                                  {"raw_error", p.raw_error},
                                  {"error_sigma", p.error_sigma},
                                  {"texels", p.texels},
                                  {"seconds", p.seconds}});
  j["chosen"] = chosen ? planned_json(*chosen) : nlohmann::json();
  j["closest"] = closest ? planned_json(*closest) : nlohmann::json();
  j["settings"] = nlohmann::json::array();
  for (const PlannedSetting& s : settings) j["settings"].push_back(planned_json(s));
  j["why"] = why;
  return j;
}

IntegratorPlan plan_integrator(const EnvMap& env, const Brdf& brdf, double max_error,
                               const std::vector<IntegratorSetting>& settings, std::uint64_t seed, double margin) {
  if (!(max_error > 0 && max_error < 1))
    throw std::invalid_argument("plan: the error budget must lie in (0, 1), not " + std::to_string(max_error));
  const auto t0 = std::chrono::steady_clock::now();
  Pilots pilots(env);
  const ErrorSample sample(4, 96, 128, seed,
                           squared_radiance_guide(pilots.integrator(kInterpolationIntegrator.method), brdf,
                                                  options_of(kInterpolationIntegrator, seed), 32));
  pilots.measure(brdf, sample, settings, seed, 128);
  if (pilots.integrators.empty()) throw std::invalid_argument("plan: no integrator setting can bake this BRDF");
  IntegratorPlan plan;
  plan.integrators = pilots.integrators;
  plan.max_error = max_error;
  plan.margin = margin;
  for (const IntegratorPilot& p : plan.integrators)
    if (p.error + p.error_sigma <= margin * max_error &&
        (!plan.chosen || p.seconds_per_texel < plan.chosen->seconds_per_texel))
      plan.chosen = p;
  plan.seconds = seconds_since(t0);
  return plan;
}

nlohmann::json IntegratorPlan::to_json() const {
  auto one = [](const IntegratorPilot& p) {
    return nlohmann::json{{"integrator", p.setting.label()},
                          {"method", p.setting.method},
                          {"samples", p.setting.samples},
                          {"reference_width", p.setting.reference_width},
                          {"error", p.error},
                          {"error_sigma", p.error_sigma},
                          {"seconds_per_texel", p.seconds_per_texel}};
  };
  nlohmann::json j = {{"max_error", max_error}, {"margin", margin}, {"seconds", seconds}};
  j["chosen"] = chosen ? one(*chosen) : nlohmann::json();
  j["integrators"] = nlohmann::json::array();
  for (const IntegratorPilot& p : integrators) j["integrators"].push_back(one(p));
  return j;
}

BakeCheck check_bake(const MapSet& set, const ViewSet& view_set, const EnvMap& env, const Brdf& brdf,
                     std::uint64_t seed, int views, int texels, int size) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto guide_integrator = make_integrator(kInterpolationIntegrator.method, env);
  const ErrorSample sample(
      views, texels, size, seed,
      squared_radiance_guide(*guide_integrator, brdf, options_of(kInterpolationIntegrator, seed), 32));
  const auto reference = make_integrator("reference", env);
  IntegratorOptions o;
  const std::vector<Vec3> truth = direct_values(*reference, brdf, o, sample);
  const SampledBlend b = sampled_blend(set, view_set, sample);
  BakeCheck c;
  const ErrorEstimate e = sample_error(sample, b.values, truth, &b.weights);
  c.error = e.value;
  c.error_sigma = e.sigma;
  c.views = views;
  c.texels = sample.count();
  c.seconds = seconds_since(t0);
  return c;
}

BudgetCheck check_bake_for_budget(const MapSet& set, const ViewSet& view_set, const EnvMap& env, const Brdf& brdf,
                                  std::uint64_t seed, double budget, const BakeCheckOptions& o) {
  if (!(budget > 0)) throw std::invalid_argument("check: the error budget must be > 0");
  if (o.views < 1 || o.max_views < o.views || o.texels < 1 || !(o.sigmas >= 0))
    throw std::invalid_argument("check: views >= 1, max_views >= views, texels >= 1 and sigmas >= 0 are needed");
  BudgetCheck out;
  for (int views = o.views;; views = std::min(2 * views, o.max_views)) {
    out.check = check_bake(set, view_set, env, brdf, seed + std::uint64_t(out.rounds), views, o.texels, o.size);
    out.seconds += out.check.seconds;
    ++out.rounds;
    const double e = out.check.error, s = out.check.error_sigma;
    if (e + o.sigmas * s <= budget) {
      out.verdict = "meets";
      break;
    }
    if (e - o.sigmas * s > budget) {
      out.verdict = "exceeds";
      break;
    }
    if (s <= o.target_sigma * budget || views >= o.max_views) {
      out.verdict = "undecided";
      break;
    }
  }
  return out;
}

}  // namespace rsibr
