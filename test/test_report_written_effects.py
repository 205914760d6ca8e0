# SPDX-License-Identifier: Apache-2.0
"""report.md shows each effect as calibration.json writes it (cold review: they disagreed)."""

from satmotor_ros.identify import calibrate
from satmotor_ros.identify.report import write_report
from satmotor_ros.identify.synthetic import generate, Injection, Plan
from satmotor_ros.model.units import LPM


def test_a_fitted_power_is_reported_with_the_json_coefficient_and_interval(tmp_path):
    cal = calibrate(generate(Plan(liquid='oil'), Injection('term:dp^0.76', 0.8 * LPM), seed=4),
                    'oil')
    summary = cal.summary()
    effect = summary['effects'][0]
    assert effect['effect'].startswith('term:dp^')
    report = write_report(cal, tmp_path, summary).read_text()
    row = next(line for line in report.splitlines() if line.startswith(f"| `{effect['effect']}`"))
    assert f"{effect['coefficient']:.5g}" in row
    assert f"[{effect['ci95'][0]:.5g}, {effect['ci95'][1]:.5g}]" in row
    lo, hi = effect['exponents_ci95']['dp']
    assert lo < 0.76 < hi and 'exponent of dp' in row
