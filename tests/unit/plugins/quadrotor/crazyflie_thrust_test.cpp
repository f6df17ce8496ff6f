// The Crazyflie firmware's thrust model: the curve's root is the voltage that gives the thrust, the
// command's limits, and the real flights: a Crazyflie of the NanoBench dataset (firmware 2025.12.1)
// logged its thrust command, battery voltage and the four motors' PWM; through the model, the
// command and the filtered voltage give the motors' mean PWM to under 1 % (median over each
// flight), and the "2.1+ propellers" set fits better than the legacy one.
#include "crazyflie_thrust.hpp"
#include "nanobench_flight.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

using ssx::quadrotor::BatteryFilter;
using ssx::quadrotor::CrazyflieThrustCurve;

namespace {

// the median of |mean motor PWM / the model's PWM - 1| over the rows with every motor running and none at the ceiling
double medianMiss(const std::map<std::string, std::vector<double>>& f, const CrazyflieThrustCurve& curve) {
  BatteryFilter battery;
  std::vector<double> misses;
  const auto& t = f.at("t");
  for (std::size_t i = 0; i < t.size(); ++i) {
    const int ticks = i == 0 ? 10 : std::max(1, static_cast<int>(std::lround((t[i] - t[i - 1]) * 1000)));
    battery.update(f.at("vbat")[i], ticks);
    const double m[] = {f.at("m1")[i], f.at("m2")[i], f.at("m3")[i], f.at("m4")[i]};
    const double model = curve.pwm(f.at("cmd_thrust")[i], battery.volts());
    if (model <= 0 || *std::min_element(m, m + 4) <= 0 || *std::max_element(m, m + 4) >= 65500) continue;
    misses.push_back(std::abs((m[0] + m[1] + m[2] + m[3]) / 4 / model - 1));
  }
  REQUIRE(misses.size() > 1000);
  std::nth_element(misses.begin(), misses.begin() + misses.size() / 2, misses.end());
  return misses[misses.size() / 2];
}

}  // namespace

TEST_CASE("crazyflie thrust: the voltage for a thrust, the command's floor and ceiling", "[quadrotor][crazyflie]") {
  const CrazyflieThrustCurve curve = CrazyflieThrustCurve::propellers21plus();
  for (const double newtons : {0.013, 0.05, 0.1, 0.12}) CHECK(curve.thrust(curve.volts(newtons)) == Approx(newtons).epsilon(1e-12));
  CHECK(curve.pwm(0.1 * 65535, 4.0) == 0);                 // 0.012 N: below the 0.012818 N floor
  CHECK(curve.pwm(30000, 1.9) == 0);                        // a battery below 2 V
  CHECK(curve.pwm(65535, 3.0) == 65535);                    // 0.12 N needs more than 3 V: full PWM
  const double full = curve.pwm(30000, 4.2), sagged = curve.pwm(30000, 3.5);
  CHECK(sagged == Approx(full * 4.2 / 3.5));                // the same thrust from a sagging battery
  CHECK(curve.volts(30000.0 / 65535 * 0.12) * 65535 / 4.2 == Approx(full));
  BatteryFilter battery;
  CHECK(battery.volts() == 4.2);
  battery.update(3.2, 100);  // 0.1 s: the filter's time constant, about
  CHECK(battery.volts() == Approx(3.2 + 1.0 * std::pow(0.99, 100)));
}

TEST_CASE("crazyflie thrust: NanoBench's logged motor PWM from its thrust command and battery", "[quadrotor][crazyflie]") {
  for (const char* name : {"B3_figure8_slow_rep1", "B3_figure8_slow_rep2", "B3_figure8_slow_rep3", "B3_figure8_fast_rep1",
                           "B3_figure8_fast_rep2"}) {
    INFO(name);
    const auto flight = ssx::test::readNanobenchFlight(name);
    const double plus = medianMiss(flight, CrazyflieThrustCurve::propellers21plus());
    const double legacy = medianMiss(flight, CrazyflieThrustCurve::legacyPropellers());
    std::printf("%s: the motors' mean PWM missed by %.2f %% (median; 2.1+ propellers), %.2f %% (legacy)\n", name,
                plus * 100, legacy * 100);
    CHECK(plus < 0.01);
    CHECK(plus < legacy);
  }
}

TEST_CASE("crazyflie thrust: the voltage agrees with a sixty-step bisection to 1e-12 V over the whole range",
          "[quadrotor][crazyflie]") {
  for (const CrazyflieThrustCurve curve :
       {CrazyflieThrustCurve::propellers21plus(), CrazyflieThrustCurve::legacyPropellers()}) {
    double worst = 0;
    for (int k = 0; k <= 2000; ++k) {
      const double newtons = curve.thrust_min + (0.2 - curve.thrust_min) * k / 2000.0;
      double lo = 0, hi = 16;
      for (int i = 0; i < 60; ++i) (curve.thrust(0.5 * (lo + hi)) < newtons ? lo : hi) = 0.5 * (lo + hi);
      worst = std::max(worst, std::abs(curve.volts(newtons) - 0.5 * (lo + hi)));
    }
    CHECK(worst < 1e-12);
  }
}

TEST_CASE("crazyflie thrust: at the voltage the compensation reads, a command delivers its thrust up to the battery's",
          "[quadrotor][crazyflie]") {
  // delivered() is the PWM path, thrust(pwm / 65535 V), without inverting the curve
  const CrazyflieThrustCurve curve = CrazyflieThrustCurve::propellers21plus();
  for (const double volts : {1.9, 2.5, 3.0, 3.7, 4.2}) {
    CAPTURE(volts);
    double worst = 0;
    for (int k = 0; k <= 1000; ++k) {
      const double u = 70000.0 * k / 1000.0 - 2000.0;  // below 0 and above 65535 too
      const double pwm = curve.pwm(u, volts);
      const double through_pwm = pwm <= 0 ? 0.0 : std::max(0.0, curve.thrust(pwm / 65535.0 * volts));
      worst = std::max(worst, std::abs(curve.delivered(u, volts) - through_pwm));
    }
    CHECK(worst < 1e-12);
  }
  CHECK(curve.delivered(65535, 3.0) == Approx(curve.thrust(3.0)));  // a weak battery: less than thrust_max
  CHECK(curve.delivered(65535, 4.2) == Approx(curve.thrust_max));
  CHECK(curve.delivered(100, 4.2) == 0);  // below thrust_min: off
}
