"""Seed ranges of the benchmark already used by a tuning or scoring set: the one registry.

A scoring set is run once, on seeds no tuning, no study and no earlier scoring run has seen; a scenario
that scores (``scenarios/calibration_validation.py``, ``scenarios/sim_to_real_loop.py``) refuses a seed
in a range listed here.  A range is added when its set has been scored (or looked at while a method was
built); it is never removed.  Study of a failure on a spent range is fine; scoring on it is not.
"""

from __future__ import annotations

#: (first seed, next free seed, what spent it)
SPENT = (
    (20000, 21000, "diagnosis validation: the tuning set"),
    (30000, 31000, "diagnosis validation: scoring"),
    (50000, 51000, "diagnosis validation: scoring"),
    (70000, 71000, "diagnosis validation: scoring"),
    (90000, 91000, "diagnosis validation: scoring"),
    (110000, 111000, "diagnosis validation: scoring"),
    (130000, 131000, "diagnosis validation: scoring"),
    (150000, 151000, "diagnosis validation: scoring"),
    (170000, 171000, "diagnosis validation: scoring"),
    (210000, 211000, "calibration validation: first scoring run (reports/calibration_validation/spent)"),
    (230000, 231000, "diagnosis validation: scoring"),
    (250000, 251000, "diagnosis validation: scoring"),
    (350000, 351000, "sensor-set scoring"),
    (450000, 451000, "sensor-set scoring"),
    (560000, 561000, "calibration validation: second scoring run, then studied"),
    (570000, 573000, "sim_to_real_loop: scored and studied while the parameter_mismatch refit was rebuilt"),
    (580000, 590000, "monitor validation: scoring"),
    (590000, 591000, "calibration validation: third scoring run (reports/calibration_validation/report.md), then studied"),
    (600000, 601000, "sim_to_real_loop: scored (reports/sim_to_real_loop/ of session 10)"),
    (610000, 611000, "calibration validation: fourth scoring run (reports/calibration_validation/report.md)"),
    (620000, 621000, "sim_to_real_loop: scored (reports/sim_to_real_loop/)"),
    (300000, 300100, "the third held-back set's classes made with the generator (docs/history.md), studied"),
    (700000, 700100, "replay / simulate / reported shrink on five logs (benchmarks/replay/measure_shrink.py)"),
    (710000, 710100, "monitor gap levels on no-effect logs (benchmarks/monitor/gap_levels.py)"),
    (820000, 821000, "independent truth: first scoring run (reports/independent_truth/spent/820000/)"),
    (840000, 841000, "independent truth: second scoring run (reports/independent_truth/)"),
    (850000, 851000, "diagnosis validation: scoring (reports/diagnosis_validation/scoring/spent/850000/)"),
    (860000, 861000, "diagnosis validation: scoring (reports/diagnosis_validation/scoring/spent/860000/)"),
    (880000, 881000, "diagnosis validation: scoring (reports/diagnosis_validation/scoring/spent/880000/)"),
    (890000, 891000, "diagnosis validation: scoring on the 20 ms replay step (reports/diagnosis_validation/scoring/spent/890000/)"),
    (900000, 901000, "diagnosis validation: scoring with the draws' disagreement rule (reports/diagnosis_validation/scoring/spent/900000/), "
                     "then its misses replayed at the 10 ms step and without the rule, studied"),
    (870000, 871000, "independent truth: third scoring run (reports/independent_truth/spent/870000/)"),
    (910000, 911000, "independent truth: fourth scoring run, two per class (reports/independent_truth/spent/910000/)"),
    (920000, 921000, "diagnosis validation: scoring on the final tree of session 15 (reports/diagnosis_validation/scoring/), "
                     "then its misses replayed at the 10 ms step and without the draws' rule, studied"),
    (930000, 931000, "independent truth: fifth scoring run, two per class (reports/independent_truth/spent/930000/), "
                     "then its parameter_mismatch refits and quantised log studied"),
    (940000, 941000, "diagnosis validation: scoring of session 16 (reports/diagnosis_validation/scoring/spent/940000/), and the same "
                     "logs diagnosed by the code of 39b1208 (issue 32's A/B), then 940018's lever arm studied (spent/940000)"),
    (950000, 951000, "independent truth: sixth scoring run, two per class (reports/independent_truth/spent/950000/)"),
    (980000, 981000, "independent truth: seventh scoring run on session 16's final tree, two per class "
                     "(reports/independent_truth/)"),
    (960000, 961000, "diagnosis validation: scored on 4ec47c9 and diagnosed by 39b1208 (issue 32's A/B), then two of "
                     "its runs studied (960024's string damping fit, 960029's warming seal); not committed"),
    (970000, 971000, "diagnosis validation: scoring of session 16's final tree (reports/diagnosis_validation/scoring/), "
                     "and the same logs diagnosed by 39b1208 (issue 32's A/B: benchmarks/diagnosis/scoring_ab.json)"),
    (990000, 991000, "independent truth: a scoring run on e9d7c9c (session 17), then its param_friction 990000 (the "
                     "stepwise refit stopped by the noise test in a stand-in's valley), string_boucwen 990001 and "
                     "mru_filter studied; not committed"),
    (1000000, 1001000, "independent truth: ninth scoring run on session 17's final diagnosis "
                       "(reports/independent_truth/spent/1000000/; its sensor_offset, string_second_mode and "
                       "formation_hardening cases studied in session 18)"),
    (1010000, 1011000, "diagnosis validation: scoring of session 17's final diagnosis (reports/diagnosis_validation/"
                       "scoring/spent/1010000/), and the same logs diagnosed by 39b1208 "
                       "(benchmarks/diagnosis/scoring_ab.json)"),
    (1020000, 1021000, "independent truth: tenth scoring run, session 18, on 486820a (an inconclusive verdict's "
                       "component from the held-out term) (reports/independent_truth/spent/1020000/; its mru_filter cases "
                       "studied after scoring: the high-pass corner's rescan)"),
    (1040000, 1041000, "independent truth: eleventh scoring run, session 18, on 2eaae54 (the corner's rescan) "
                       "(reports/independent_truth/spent/1040000/; its string_boucwen and line_dynamics cases studied "
                       "in session 19: the hysteretic and inertance laws)"),
    (1050000, 1051000, "independent truth: twelfth scoring run, session 19, on aa19173 (the hysteretic and inertance "
                       "laws) (reports/independent_truth/spent/1050000/; its param_gas cases studied: the refit-first "
                       "rule)"),
    (1060000, 1061000, "diagnosis validation: scoring of session 19's diagnosis before the refit-first rule, 0335925 "
                       "(reports/diagnosis_validation/scoring/spent/1060000/)"),
    (1070000, 1071000, "independent truth: thirteenth scoring run, session 19, on c32d315 (the refit-first rule) "
                       "(reports/independent_truth/)"),
    (1080000, 1081000, "diagnosis validation: scoring of session 19's diagnosis, c32d315 "
                       "(reports/diagnosis_validation/scoring/)"),
    (1090000, 1091000, "independent truth: a run on 82c2e60 stopped after 27 cases (the hysteretic law's unbounded "
                       "stiffness diverged in the suite); its printed verdicts were seen, not committed"),
    (1100000, 1101000, "independent truth: fourteenth scoring run, session 19, on 05f9518 (the share-bounded "
                       "hysteretic law) (reports/independent_truth/)"),
    (1030000, 1031000, "diagnosis validation: scoring of session 18's diagnosis, 2eaae54 (reports/diagnosis_validation/"
                       "scoring/)"),
    (9000000, 9000100, "independent truth: smoke runs while it was written"),
    (830000, 830100, "string_damping against a rate-independent (dry, F_y tanh(dv/eps)) string element, a scratch "
                     "truth law of the family helper's (issue 30 item 4), studied"),
)


def spent(seeds) -> list:
    """The spent ranges (as ``"first+"`` strings) that any of ``seeds`` falls in; empty: all fresh.

    Parameters
    ----------
    seeds : iterable of int
        The seeds a run would use.
    """
    seeds = list(seeds)
    return [f"{a}+" for a, b, _ in SPENT if any(a <= s < b for s in seeds)]
