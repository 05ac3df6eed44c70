#include "plan/bake_plan.h"

#include "bake/brdf_spec.h"
#include "bake/integrator.h"
#include "bake/map_set_bake.h"
#include "core/patterns.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace rsibr {
namespace {

EnvMap sky(const Vec3& sun, int width) {
  return render_pattern(
      patterns::sun_and_sky(sun.normalized(), 0.1, Vec3(200, 190, 150), Vec3(0.3, 0.5, 1.0), Vec3(0.9, 0.8, 0.6)),
      Layout(LayoutKind::LatLong, width, width / 2), 2);
}

// A small plan: few candidates, a small pilot.
BakePlanOptions small(double budget) {
  BakePlanOptions o;
  o.max_error = budget;
  o.view_sets = {"icosa", "42", "162"};
  o.sizes = {16, 32};
  o.integrators = {{"reference", 0, 16}, {"reference", 0, 0}, {"mis", 16, 0}, {"fis", 32, 0}, {"sh", 0, 0}};
  o.pilot_views = 8;
  o.pilot_texels = 24;
  o.pilot_size = 32;
  o.confirm_views = 16;
  return o;
}

// A plan of one candidate: the small plan with one view set, size and integrator setting.
BakePlanOptions one_candidate(double budget, const std::string& views, int res, const IntegratorSetting& integrator) {
  BakePlanOptions o = small(budget);
  o.view_sets = {views};
  o.sizes = {res};
  o.integrators = {integrator};
  return o;
}

MapSet bake(const EnvMap& env, const Brdf& brdf, const BakeSetting& s) {
  const auto integrator = make_integrator(s.integrator.method, env);
  MapSetBakeOptions o;
  o.res = s.res;
  o.integrator.samples = std::max(1, s.integrator.samples);
  o.integrator.reference_width = s.integrator.reference_width;
  return bake_map_set(brdf, *integrator, ViewSet::named(s.views), o);
}

// The property the planner is for: the setting it picks, baked in full, meets the budget at novel
// views it never saw, on environments and BRDFs chosen here at random.
TEST(BakePlan, ThePlannedSettingMeetsItsBudgetAtFreshNovelViews) {
  const std::vector<std::pair<Vec3, std::string>> cases = {
      {Vec3(0.3, 0.8, 0.2), "{type: lambert, albedo: [0.7, 0.6, 0.5]}"},
      {Vec3(-0.6, 0.3, 0.5), "{type: ggx, roughness: 0.5, fresnel: {type: schlick, f0: [0.9, 0.7, 0.5]}}"},
  };
  for (const auto& [sun, spec] : cases) {
    const EnvMap env = sky(sun, 64);
    const auto brdf = parse_brdf(spec);
    const BakePlan plan = plan_bake(env, *brdf, small(0.1));
    ASSERT_TRUE(plan.chosen) << spec << "\n" << plan.why << plan.to_json().dump(1);
    EXPECT_LE(plan.chosen->upper_error, plan.options.margin * 0.1);
    ASSERT_TRUE(plan.chosen->measured_error && plan.chosen->measured_sigma);  // a measurement decides
    EXPECT_DOUBLE_EQ(plan.chosen->upper_error,
                     *plan.chosen->measured_error + plan.options.sigmas * *plan.chosen->measured_sigma);
    const MapSet set = bake(env, *brdf, plan.chosen->setting);
    const BakeCheck check = check_bake(set, ViewSet::named(plan.chosen->setting.views), env, *brdf, 99, 8, 32, 32);
    EXPECT_LE(check.error, 0.1) << spec << ": predicted " << plan.chosen->error << "\n" << plan.why;
  }
}

// The budget check decides: far under or over the budget one round settles it; at the budget (the
// first round's own estimate) it takes rounds of twice the views, and its verdict follows its rule
// on the last round's numbers.
TEST(BakePlan, TheBudgetCheckTakesMoreViewsOnlyWhereTheAnswerIsClose) {
  const EnvMap env = sky(Vec3(0.3, 0.7, 0.4), 32);
  const auto brdf = parse_brdf("{type: ggx, roughness: 0.4, fresnel: {type: schlick, f0: [0.9, 0.7, 0.5]}}");
  BakeSetting setting;
  setting.views = "icosa";
  setting.res = 16;
  setting.integrator = {"reference", 0, 16};
  const MapSet set = bake(env, *brdf, setting);
  const ViewSet views = ViewSet::named("icosa");
  BakeCheckOptions o;
  o.texels = 24;
  o.size = 32;
  o.max_views = 32;
  const BakeCheck first = check_bake(set, views, env, *brdf, 5, o.views, o.texels, o.size);
  ASSERT_GT(first.error, 0.0);
  ASSERT_GT(first.error_sigma, 0.0);

  const BudgetCheck easy = check_bake_for_budget(set, views, env, *brdf, 5, 10 * first.error, o);
  EXPECT_EQ(easy.verdict, "meets");
  EXPECT_EQ(easy.rounds, 1);
  EXPECT_EQ(easy.check.error, first.error);  // round 0 is check_bake with the same seed
  const BudgetCheck hard = check_bake_for_budget(set, views, env, *brdf, 5, 0.1 * first.error, o);
  EXPECT_EQ(hard.verdict, "exceeds");
  EXPECT_EQ(hard.rounds, 1);

  const BudgetCheck close = check_bake_for_budget(set, views, env, *brdf, 5, first.error, o);
  EXPECT_GE(close.rounds, 2);
  EXPECT_EQ(close.check.views, std::min(o.max_views, o.views << (close.rounds - 1)));
  const double e = close.check.error, sd = close.check.error_sigma, b = first.error;
  const std::string rule = e + 2 * sd <= b ? "meets" : e - 2 * sd > b ? "exceeds" : "undecided";
  EXPECT_EQ(close.verdict, rule) << e << " +- " << sd << " against " << b;
  if (close.verdict == "undecided") {
    EXPECT_TRUE(sd <= 0.1 * b || close.check.views == o.max_views);
  }
  EXPECT_GE(close.seconds, close.check.seconds);

  BakeCheckOptions bad = o;
  bad.max_views = 4;
  EXPECT_THROW(check_bake_for_budget(set, views, env, *brdf, 5, 0.02, bad), std::invalid_argument);
  EXPECT_THROW(check_bake_for_budget(set, views, env, *brdf, 5, 0.0, o), std::invalid_argument);
}

TEST(BakePlan, NoCheaperSettingIsPredictedToMeetTheBudget) {
  const EnvMap env = sky(Vec3(0.1, 0.9, -0.3), 64);
  const auto brdf = parse_brdf("{type: ggx, roughness: 0.5, fresnel: {type: schlick, f0: [0.9, 0.8, 0.6]}}");
  BakePlanOptions o = small(0.15);
  o.every_pair = true;
  o.confirm_max_views = o.confirm_views;  // one round: the screen is what this test is about
  o.integrators.push_back({"fis", 8, 0});
  o.integrators.push_back({"fis", 128, 0});
  const BakePlan plan = plan_bake(env, *brdf, o);
  ASSERT_TRUE(plan.chosen) << plan.why << plan.to_json().dump();
  ASSERT_EQ(plan.settings.size(), 3u * 2u * 6u);  // sh cannot bake GGX: left out
  // e_interp is measured with the cheapest FIS setting of the pilot whose own error is within a
  // third of the planned budget (the most accurate FIS when none is), and its own error is the
  // pilot's for that setting: the same texels, integrator and seed.
  const IntegratorPilot* cheapest = nullptr;
  const IntegratorPilot* most_accurate = nullptr;
  for (const IntegratorPilot& p : plan.integrators) {
    if (p.setting.method != "fis") continue;
    if (!most_accurate || p.error < most_accurate->error) most_accurate = &p;
    if (p.error <= o.margin * o.max_error / 3 && (!cheapest || p.seconds_per_texel < cheapest->seconds_per_texel))
      cheapest = &p;
  }
  const IntegratorPilot* expected = cheapest ? cheapest : most_accurate;
  ASSERT_TRUE(expected);
  EXPECT_EQ(plan.interpolation_integrator.label(), expected->setting.label());
  EXPECT_NEAR(plan.interpolation_integrator_error, expected->error, 1e-12);
  double previous = 0;
  double factor = 0.5, mis_factor = 1.0 / 3.0;
  bool measured_any = false, mis_measured = false;
  for (const PlannedSetting& s : plan.settings) {
    EXPECT_GE(s.seconds, previous);  // sorted by predicted time
    previous = s.seconds;
    ASSERT_TRUE(s.interpolation_error);
    if (s.seconds < plan.chosen->seconds) {
      // Cheaper: screened out by the model, or measured and over the budget with its sigma.
      EXPECT_FALSE(s.meets) << s.setting.views << " " << s.setting.res;
      if (s.measured_error) {
        EXPECT_GT(*s.measured_error + o.sigmas * *s.measured_sigma, o.margin * o.max_error);
      }
      // A confirmation stopped early proved the candidate over 1.5x the planned budget.
      if (s.measured_at_least) {
        EXPECT_FALSE(s.measured_error);
        EXPECT_GT(*s.measured_at_least, 1.5 * o.margin * o.max_error);
      }
      // The screen is optimistic (mis integration error at a third, interpolation at half until
      // measurements calibrate them: the least factors with measured^2 = (a e_interp)^2 + (b
      // e_int)^2 among the candidates measured before it, a from those whose screened interpolation
      // part is at least their integration part, b from mis ones where it is less): every candidate
      // it lets through is measured, not rejected by the model alone.
      const bool mis = s.setting.integrator.method == "mis";
      const double ie = mis ? mis_factor * s.integration_error : s.integration_error;
      ASSERT_TRUE(s.screened_error);
      EXPECT_NEAR(s.interpolation_screen, factor, 1e-12) << s.setting.views << " " << s.setting.res;
      EXPECT_NEAR(s.mis_screen, mis_factor, 1e-12) << s.setting.views << " " << s.setting.res;
      EXPECT_NEAR(*s.screened_error, std::hypot(factor * *s.interpolation_error, ie), 1e-12);
      if (*s.screened_error <= o.margin * o.max_error) {
        EXPECT_TRUE(s.measured_error || s.measured_at_least)
            << s.setting.views << " " << s.setting.res << " " << s.setting.integrator.label();
      } else {
        EXPECT_FALSE(s.measured_error || s.measured_at_least) << s.setting.views << " " << s.setting.res;
      }
      // A stopped measurement calibrates with its lower bound.
      const double ip = factor * *s.interpolation_error;
      const bool measured = s.measured_error || s.measured_at_least;
      const double m = s.measured_error ? *s.measured_error : s.measured_at_least.value_or(0.0);
      if (measured && ip >= ie && *s.interpolation_error > 0) {
        const double a = std::sqrt(std::max(0.0, m * m - ie * ie)) / *s.interpolation_error;
        factor = measured_any ? std::min(factor, a) : a;
        measured_any = true;
      } else if (measured && mis && s.integration_error > 0) {
        const double b = std::sqrt(std::max(0.0, m * m - ip * ip)) / s.integration_error;
        mis_factor = mis_measured ? std::min(mis_factor, b) : b;
        mis_measured = true;
      }
    }
  }
  EXPECT_TRUE(measured_any);  // a measurement calibrated the screen before the choice
  ASSERT_TRUE(plan.chosen->measured_error);
  EXPECT_LE(*plan.chosen->measured_error + o.sigmas * *plan.chosen->measured_sigma, o.margin * o.max_error);
  EXPECT_DOUBLE_EQ(plan.chosen->upper_error, *plan.chosen->measured_error + o.sigmas * *plan.chosen->measured_sigma);
  // More views interpolate better at the same size.
  auto interp = [&](const std::string& views, int res) {
    for (const InterpolationPilot& p : plan.interpolation)
      if (p.views == views && p.res == res) return p.error;
    return -1.0;
  };
  EXPECT_LT(interp("42", 32), interp("icosa", 32));
}

// Where mis's noise is the error (a smooth BRDF, many views), the screen's mis factor becomes what
// the first mis measurement implies, and the next mis candidate is screened with it.
TEST(BakePlan, TheMisScreenTakesTheFactorItsMeasurementsImply) {
  const EnvMap env = sky(Vec3(0.2, 0.8, 0.4), 64);
  const auto brdf = parse_brdf("{type: lambert, albedo: [0.6, 0.6, 0.6]}");
  BakePlanOptions o = small(0.03);
  o.view_sets = {"162"};
  o.sizes = {16};
  o.integrators = {{"mis", 4, 0}, {"mis", 16, 0}, {"mis", 64, 0}, {"reference", 0, 0}};
  o.stop_early = false;  // whole measurements: the factor is what a measured error implies
  const BakePlan plan = plan_bake(env, *brdf, o);
  EXPECT_EQ(plan.interpolation_integrator.label(), "fis 64 samples");  // no FIS in the pilot: the default
  std::vector<const PlannedSetting*> mis;
  for (const PlannedSetting& s : plan.settings)
    if (s.setting.integrator.method == "mis" && s.measured_error) mis.push_back(&s);
  ASSERT_GE(mis.size(), 2u) << plan.why << plan.to_json()["settings"].dump(0);
  const PlannedSetting& first = *mis[0];
  EXPECT_DOUBLE_EQ(first.mis_screen, 1.0 / 3.0);
  const double ip = first.interpolation_screen * *first.interpolation_error;
  ASSERT_LT(ip, first.mis_screen * first.integration_error);  // the integration part is the larger
  const double m = *first.measured_error;
  const double b = std::sqrt(m * m - ip * ip) / first.integration_error;
  EXPECT_NEAR(mis[1]->mis_screen, b, 1e-12);
  EXPECT_NEAR(*mis[1]->screened_error,
              std::hypot(mis[1]->interpolation_screen * *mis[1]->interpolation_error, b * mis[1]->integration_error),
              1e-12);
}

// The integrator alone (maps baked at the frames they are used at): the cheapest setting per texel
// whose measured error plus its standard error fits, and none cheaper that fits.
TEST(IntegratorPlanTest, TheCheapestSettingWhoseErrorAndSigmaFitIsTaken) {
  const EnvMap env = sky(Vec3(0.4, 0.6, 0.3), 64);
  const auto brdf = parse_brdf("{type: ggx, roughness: 0.4, fresnel: {type: schlick, f0: [0.9, 0.8, 0.6]}}");
  const std::vector<IntegratorSetting> settings = {{"reference", 0, 16}, {"reference", 0, 32}, {"reference", 0, 0},
                                                   {"mis", 8, 0},        {"mis", 64, 0},       {"fis", 32, 0}};
  const IntegratorPlan plan = plan_integrator(env, *brdf, 0.03, settings, 5);
  ASSERT_TRUE(plan.chosen) << plan.to_json().dump(1);
  EXPECT_LE(plan.chosen->error + plan.chosen->error_sigma, 0.03);
  for (const IntegratorPilot& p : plan.integrators) {
    EXPECT_GE(p.error_sigma, 0.0);
    if (p.seconds_per_texel < plan.chosen->seconds_per_texel) {
      EXPECT_GT(p.error + p.error_sigma, 0.03) << p.setting.label();
    }
    if (p.setting.label() == "reference (full)") {
      EXPECT_EQ(p.error, 0.0);
    }
  }
  EXPECT_FALSE(plan_integrator(env, *brdf, 1e-6, {{"mis", 8, 0}}, 5).chosen);
}

TEST(BakePlan, AnUnreachableBudgetChoosesNothingAndSaysSo) {
  const EnvMap env = sky(Vec3(0.2, 0.7, 0.4), 32);
  const auto brdf = parse_brdf("{type: ggx, roughness: 0.1, fresnel: {type: schlick, f0: [0.9, 0.9, 0.9]}}");
  const BakePlan plan = plan_bake(env, *brdf, small(1e-5));
  EXPECT_FALSE(plan.chosen);
  // Nothing was measured, so the confirmation sample and its truth were never made.
  EXPECT_EQ(plan.confirm_texels, 0);
  EXPECT_LE(plan.truth_texels, plan.options.pilot_views * plan.options.pilot_texels);
  EXPECT_NE(plan.why.find("no setting"), std::string::npos);
  EXPECT_TRUE(plan.to_json()["chosen"].is_null());
}

// When the screen lets nothing through but its least screened candidate is within twice the planned
// budget, that one candidate is measured, so that the plan names the closest setting.
TEST(BakePlan, WhenTheScreenPassesNothingItsLeastScreenedCandidateIsMeasured) {
  const EnvMap env = sky(Vec3(0.3, 0.6, 0.5), 32);
  const auto brdf = parse_brdf("{type: ggx, roughness: 0.3, fresnel: {type: schlick, f0: [0.9, 0.8, 0.6]}}");
  BakePlanOptions o = small(0.05);
  o.every_pair = true;
  o.max_confirmations = 0;  // the screen alone: every candidate's screened error, nothing measured
  const BakePlan screen_only = plan_bake(env, *brdf, o);
  // The full reference is left out (its measurement costs the full quadrature at every texel read).
  auto full_reference = [](const PlannedSetting& s) {
    return s.setting.integrator.method == "reference" && s.setting.integrator.reference_width == 0;
  };
  double least = 1e300;
  for (const PlannedSetting& s : screen_only.settings) {
    EXPECT_FALSE(s.measured_error);
    if (s.screened_error && !full_reference(s)) least = std::min(least, *s.screened_error);
  }
  ASSERT_LT(least, 1.0);
  o.max_confirmations = 32;
  o.max_error = least / 1.5 / o.margin;  // the least screened error is 1.5x the planned budget
  const BakePlan plan = plan_bake(env, *brdf, o);
  int measured = 0;
  for (const PlannedSetting& s : plan.settings)
    if (s.measured_error) {
      ++measured;
      EXPECT_DOUBLE_EQ(*s.screened_error, least);
      EXPECT_FALSE(full_reference(s));
    }
  EXPECT_EQ(measured, 1);
  ASSERT_TRUE(plan.chosen || plan.closest);
  if (!plan.chosen) {
    EXPECT_DOUBLE_EQ(*plan.closest->screened_error, least);
  }
  // Beyond twice the plan, nothing is measured.
  o.max_error = least / 2.5 / o.margin;
  for (const PlannedSetting& s : plan_bake(env, *brdf, o).settings) EXPECT_FALSE(s.measured_error);
}

// When nothing meets the budget, the plan names the measured candidate nearest to it: here every
// measurement's upper bound is pushed past the budget (100 standard errors) and the plan stops after
// at most two measurements (the calibrated screen may let fewer through).
TEST(BakePlan, WithoutAChoiceTheClosestMeasuredSettingIsNamed) {
  const EnvMap env = sky(Vec3(0.2, 0.7, 0.4), 32);
  const auto brdf = parse_brdf("{type: phong, albedo: [0.6, 0.5, 0.4], exponent: 20}");
  BakePlanOptions o = small(0.05);
  o.sigmas = 100;
  o.max_confirmations = 2;
  const BakePlan plan = plan_bake(env, *brdf, o);
  ASSERT_FALSE(plan.chosen);
  ASSERT_TRUE(plan.closest) << plan.why;
  int measured = 0;
  for (const PlannedSetting& s : plan.settings) {
    if (!s.measured_error) continue;
    ++measured;
    EXPECT_GE(s.upper_error, plan.closest->upper_error);
  }
  EXPECT_GE(measured, 1);
  EXPECT_LE(measured, 2);
  EXPECT_NE(plan.why.find("closest: " + std::to_string(plan.closest->setting.view_count)), std::string::npos)
      << plan.why;
  EXPECT_EQ(plan.to_json()["closest"]["upper_error"].get<double>(), plan.closest->upper_error);
  EXPECT_TRUE(plan_bake(env, *brdf, small(1e-5)).to_json()["closest"].is_null());  // nothing was measured
}

// Confirmations that miss by far stop early with a lower bound; when every one stopped and none was
// chosen, the one stopped at the least bound is measured in full, and that is the closest setting,
// with the error a plan that never stops measures for it.
TEST(BakePlan, WhenEveryConfirmationStoppedEarlyTheLeastBoundIsMeasuredInFull) {
  const EnvMap env = sky(Vec3(0.2, 0.7, 0.4), 32);
  const auto brdf = parse_brdf("{type: phong, albedo: [0.6, 0.5, 0.4], exponent: 20}");
  // 12 views interpolate this lobe at about 7%; the screen counts that at half (3.4%), within the
  // planned 3.6%, and the measurement exceeds 1.5x that.
  BakePlanOptions o = one_candidate(0.04, "icosa", 32, {"fis", 32, 0});
  const BakePlan plan = plan_bake(env, *brdf, o);
  ASSERT_FALSE(plan.chosen) << plan.why;
  ASSERT_TRUE(plan.closest) << plan.why;
  int whole = 0;
  for (const PlannedSetting& s : plan.settings) {
    EXPECT_FALSE(s.measured_at_least);  // the only stopped one was measured again in full
    if (s.measured_error) ++whole;
  }
  EXPECT_EQ(whole, 1);
  ASSERT_TRUE(plan.closest->measured_error);
  EXPECT_GT(*plan.closest->measured_error, 1.5 * o.margin * o.max_error);  // it had stopped
  BakePlanOptions full = o;
  full.stop_early = false;
  const BakePlan never = plan_bake(env, *brdf, full);
  ASSERT_TRUE(never.closest);
  EXPECT_EQ(never.closest->setting.res, plan.closest->setting.res);
  EXPECT_EQ(*never.closest->measured_error, *plan.closest->measured_error);
  EXPECT_EQ(*never.closest->measured_sigma, *plan.closest->measured_sigma);
}

// What a bake uses: the choice; without one, the closest measured setting only when its measured
// error is within the budget itself (the reserve and the standard errors left to the bake's check).
TEST(BakePlan, ABakeTakesTheChoiceElseTheClosestMeasuredSettingWithinTheBudget) {
  BakePlan plan;
  plan.options.max_error = 0.02;
  PlannedSetting closest;
  closest.setting = {"fib324", 324, 64, {"fis", 128, 0}};
  closest.measured_error = 0.0166;
  closest.measured_sigma = 0.0040;
  closest.upper_error = 0.0166 + 0.5 * 0.0040;  // over margin x budget = 0.018: no choice
  bool fallback = true;
  EXPECT_EQ(setting_to_bake(plan, &fallback), nullptr);  // nothing measured
  EXPECT_FALSE(fallback);
  plan.closest = closest;
  const PlannedSetting* s = setting_to_bake(plan, &fallback);
  ASSERT_NE(s, nullptr);
  EXPECT_TRUE(fallback);
  EXPECT_EQ(s->setting.view_count, 324);
  plan.closest->measured_error = 0.0201;  // over the budget itself: nothing to bake
  EXPECT_EQ(setting_to_bake(plan, &fallback), nullptr);
  plan.closest->measured_error = std::nan("");
  EXPECT_EQ(setting_to_bake(plan, &fallback), nullptr);
  plan.closest->measured_error.reset();
  EXPECT_EQ(setting_to_bake(plan, &fallback), nullptr);
  PlannedSetting chosen = closest;
  chosen.setting.view_count = 642;
  chosen.meets = true;
  plan.chosen = chosen;
  plan.closest->measured_error = 0.0166;
  s = setting_to_bake(plan, &fallback);
  ASSERT_NE(s, nullptr);
  EXPECT_FALSE(fallback);
  EXPECT_EQ(s->setting.view_count, 642);
  EXPECT_EQ(setting_to_bake(plan), s);  // the flag is optional
}

TEST(BakePlan, TheFullReferenceHasNoIntegrationErrorAndCoarserWidthsHaveMore) {
  const EnvMap env = sky(Vec3(0.5, 0.5, 0.5), 64);
  const auto brdf = parse_brdf("{type: lambert, albedo: [0.8, 0.8, 0.8]}");
  const BakePlan plan = plan_bake(env, *brdf, small(0.05));
  double full = -1, coarse = -1;
  for (const IntegratorPilot& p : plan.integrators) {
    if (p.setting.label() == "reference (full)") full = p.error;
    if (p.setting.label() == "reference width 16") coarse = p.error;
    EXPECT_GT(p.seconds_per_texel, 0.0) << p.setting.label();
  }
  EXPECT_EQ(full, 0.0);
  EXPECT_GT(coarse, 0.0);
}

TEST(BakePlan, BadBudgetsAndEmptyChoicesAreRefused) {
  const EnvMap env = sky(Vec3(0, 1, 0), 32);
  const auto brdf = parse_brdf("{type: lambert, albedo: [0.8, 0.8, 0.8]}");
  for (double bad : {0.0, -0.1, 1.0, std::nan("")})
    EXPECT_THROW(plan_bake(env, *brdf, small(bad)), std::invalid_argument);
  BakePlanOptions o = small(0.05);
  o.sizes.clear();
  EXPECT_THROW(plan_bake(env, *brdf, o), std::invalid_argument);
  o = small(0.05);
  o.integrators = {{"sh", 0, 0}};
  const auto ggx = parse_brdf("{type: ggx, roughness: 0.3, fresnel: {type: none}}");
  EXPECT_THROW(plan_bake(env, *ggx, o), std::invalid_argument);  // nothing can bake it
  o = small(0.05);
  o.confirm_views = -1;
  EXPECT_THROW(plan_bake(env, *brdf, o), std::invalid_argument);
  o = small(0.05);
  o.confirm_max_views = -1;
  EXPECT_THROW(plan_bake(env, *brdf, o), std::invalid_argument);
}

// Every option outside its range is refused, and before the pilot: with a BRDF that no integrator
// of the plan can bake, the message is the option's, not the pilot's.
TEST(BakePlan, OptionsOutOfRangeAreRefusedBeforeThePilot) {
  const EnvMap env = sky(Vec3(0, 1, 0), 32);
  const auto ggx = parse_brdf("{type: ggx, roughness: 0.3, fresnel: {type: none}}");
  auto refusal = [&](const std::function<void(BakePlanOptions&)>& change) -> std::string {
    BakePlanOptions o = small(0.05);
    o.integrators = {{"sh", 0, 0}};  // the pilot would refuse: sh bakes Lambert only
    change(o);
    try {
      plan_bake(env, *ggx, o);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(refusal([](BakePlanOptions&) {}).find("no integrator setting"), std::string::npos);
  const std::vector<std::function<void(BakePlanOptions&)>> bad = {
      [](BakePlanOptions& o) { o.max_error = 1.5; },      [](BakePlanOptions& o) { o.view_sets.clear(); },
      [](BakePlanOptions& o) { o.integrators.clear(); },  [](BakePlanOptions& o) { o.margin = 0; },
      [](BakePlanOptions& o) { o.margin = 1.1; },         [](BakePlanOptions& o) { o.sizes = {16, 1}; },
      [](BakePlanOptions& o) { o.view_sets = {"nope"}; }, [](BakePlanOptions& o) { o.sigmas = -1; },
      [](BakePlanOptions& o) { o.confirm_views = -1; },   [](BakePlanOptions& o) { o.confirm_max_views = -1; },
      [](BakePlanOptions& o) { o.guide_size = 1; },
  };
  for (std::size_t i = 0; i < bad.size(); ++i) {
    const std::string message = refusal(bad[i]);
    EXPECT_FALSE(message.empty()) << i;
    EXPECT_EQ(message.find("no integrator setting"), std::string::npos) << i << ": " << message;
  }
}

// Confirming at the pilot's own texels (confirm_views 0) and at a sample of their own both decide by
// a measurement at the sample they name; the larger sample's standard error is the smaller.
TEST(BakePlan, TheConfirmationSampleIsTheOneNamedAndMoreViewsNarrowIt) {
  const EnvMap env = sky(Vec3(0.3, 0.6, 0.5), 64);
  const auto brdf = parse_brdf("{type: ggx, roughness: 0.4, fresnel: {type: schlick, f0: [0.9, 0.7, 0.5]}}");
  // A budget the screen lets the one candidate through for.
  BakePlanOptions o = one_candidate(0.5, "162", 32, {"reference", 0, 16});
  o.confirm_views = 0;
  const BakePlan own = plan_bake(env, *brdf, o);
  o.confirm_views = 64;
  o.confirm_max_views = 64;  // one round
  const BakePlan larger = plan_bake(env, *brdf, o);
  ASSERT_EQ(own.settings.size(), 1u);
  ASSERT_EQ(larger.settings.size(), 1u);
  ASSERT_TRUE(own.settings[0].measured_error && larger.settings[0].measured_error) << own.why << larger.why;
  EXPECT_EQ(own.settings[0].measured_views, o.pilot_views);
  EXPECT_EQ(larger.settings[0].measured_views, 64);
  EXPECT_EQ(own.confirm_texels, own.truth_texels);  // the pilot's texels: no truth of its own
  EXPECT_EQ(larger.confirm_texels, larger.truth_texels - own.truth_texels);
  EXPECT_LE(larger.confirm_texels, 64 * o.pilot_texels);
  EXPECT_GT(larger.confirm_texels, 2 * own.confirm_texels);
  EXPECT_NE(*own.settings[0].measured_error, *larger.settings[0].measured_error);
  EXPECT_LT(*larger.settings[0].measured_sigma, *own.settings[0].measured_sigma);
  EXPECT_EQ(larger.to_json()["pilot"]["confirm_texels"].get<long long>(), larger.confirm_texels);
}

// The confirmation's rounds are a sequential test on the pooled estimate e +- s: a candidate one
// standard error over the planned budget is left after its first round; one that passes there is
// taken only once a round of fresh views agrees; one in between takes fresh views, doubling the
// pooled count, until the rule decides or confirm_max_views is reached.
TEST(BakePlan, AConfirmationTakesFreshViewsUntilItsRuleDecides) {
  const EnvMap env = sky(Vec3(0.3, 0.6, 0.5), 64);
  const auto brdf = parse_brdf("{type: phong, albedo: [0.6, 0.5, 0.4], exponent: 20}");
  BakePlanOptions o = one_candidate(0.5, "icosa", 32, {"fis", 32, 0});
  o.confirm_views = 16;
  o.confirm_max_views = 16;
  o.stop_early = false;
  const BakePlan one = plan_bake(env, *brdf, o);
  ASSERT_EQ(one.settings.size(), 1u);
  ASSERT_TRUE(one.settings[0].measured_error) << one.why;
  const double e0 = *one.settings[0].measured_error, s0 = *one.settings[0].measured_sigma;
  ASSERT_GT(s0, 0);
  EXPECT_EQ(one.settings[0].measured_views, 16);

  o.confirm_max_views = 128;
  auto with_planned_budget = [&](double planned) {
    BakePlanOptions b = o;
    b.max_error = planned / b.margin;
    const BakePlan p = plan_bake(env, *brdf, b);
    EXPECT_EQ(p.settings.size(), 1u);
    return p.settings.at(0);
  };
  // Within the budget at the first round: one round of fresh views more, which agrees.
  const PlannedSetting within = with_planned_budget(2 * e0 + 4 * s0);
  EXPECT_EQ(within.measured_views, 32);
  EXPECT_TRUE(within.meets);
  // A clear miss: one round.
  const PlannedSetting over = with_planned_budget(0.9 * (e0 - s0));
  EXPECT_EQ(over.measured_views, 16);
  EXPECT_FALSE(over.meets);
  EXPECT_EQ(*over.measured_error, e0);
  // Undecided at the first round (e0 - s0 <= budget < e0 + s0 / 2): pooled further, and where it
  // stopped the rule decides or the views ran out.
  const double budget = e0;
  const PlannedSetting close = with_planned_budget(budget);
  ASSERT_TRUE(close.measured_error && close.measured_sigma);
  EXPECT_GE(close.measured_views, 32);
  EXPECT_LE(close.measured_views, 128);
  const double e = *close.measured_error, s = *close.measured_sigma;
  EXPECT_NE(e, e0);
  EXPECT_LT(s, s0);
  // The reserve, (1 - margin) of the budget at the first round's 16 views, shrinks as 1 / sqrt(n).
  const double max_error = budget / o.margin;
  const double planned = max_error - (max_error - budget) * std::sqrt(16.0 / close.measured_views);
  EXPECT_EQ(close.meets, e + o.sigmas * s <= planned);
  if (close.measured_views < 128) EXPECT_TRUE(close.meets || e - s > planned) << e << " +- " << s;
}

}  // namespace
}  // namespace rsibr
