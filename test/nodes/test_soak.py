# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The soak's short version (benchmarks/soak.py, four faults, about a minute and a half):
sim_node at speed 10 and estimator_node as processes, bag_replayer looping a bag into a second
estimator_node, shaper_node on the first's estimates; four faults from a seeded schedule, each
waited for and judged before the next (``--count``: no wall-clock budget a loaded machine could
cut short) -- a restart with time going back, a 5-s SIGSTOP of estimator_node second (a stop first
met the kernels' compile ending, a restart of its own), a parameter storm with invalid values, a
5000-message burst: after the stop, input taken again and an estimate within two estimator
windows of stream and an analysis hop (over shared memory the node went deaf for good after such
a stop about one time in two: docs/nodes.md#never-deaf); every fault recovered (an estimate
within 3 windows of stream, measured in the simulator's time, not in steady seconds), every call
answered, every burst message received or counted, the counters' identities, what the replay
estimator and the shaper took of what was sent to them, no traceback, SIGINT exit 0 within 2 s
for every node (issue 40)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from vib_estimator.core.ambient import hop_s
from vib_estimator.nodes.cadence import WATCHDOG_MIN_S

SOAK = Path(__file__).resolve().parents[2] / 'benchmarks' / 'soak.py'


def test_a_minute_of_faults(tmp_path):
    out = tmp_path / 'soak.json'
    # --minutes: a limit only (a fault that cannot start before it is a problem)
    args = ['--count', '4', '--minutes', '5', '--fault-every', '10', '--stop-s', '5']
    args += ['--faults', 'stop,restart,storm,burst', '--seed', '15']
    run = subprocess.run(
        [sys.executable, str(SOAK), *args, '--json', str(out)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert out.exists(), f'exit {run.returncode}: ' + run.stdout[-4000:] + run.stderr[-4000:]
    fig = json.loads(out.read_text())
    assert run.returncode in (0, 1), run.stdout + run.stderr
    assert fig['problems'] == [], run.stdout
    assert all(code == 0 and seconds <= 2.0 for code, seconds in fig['exits'].values())
    assert set(fig['exits']) == {
        'estimator_node',
        'sim_node',
        'replay_estimator',
        'bag_replayer',
        'shaper_node',
    }
    kinds = [f['kind'] for f in fig['faults']]
    assert kinds == ['restart', 'stop', 'storm', 'burst'], kinds
    assert all(f['recovered'] is True for f in fig['faults']), fig['faults']
    # never deaf: after the node's own stall, input again and estimates within the windows
    stop = next(f for f in fig['faults'] if f['kind'] == 'stop')
    assert stop['input_s'] == stop['input_s'] and stop['recovered'] is True, run.stdout
    assert stop['windows'] <= 2.0 + hop_s(stop['window_s']) / stop['window_s'], run.stdout
    # no silence it had to answer but those the schedule makes: the simulator's restart (a
    # publisher matched -- the new simulator's, before its first sample -- past the watchdog's
    # wait, as a loaded machine can) and the burst's stopped simulator before and after the
    # burst (the soak waits on the node's counters there) -- and one more: a re-creation after
    # silences of 0.4-1.0 s only was seen in 2 of about 8 local suite runs (none in CI), its
    # cause not found (messages stamped behind the last one were not counted taken by the
    # watchdog, fixed: cadence.taken_at; the soak now says when: resubscribed_at). A watchdog
    # that fires again and again fails here.
    restart = next(f for f in fig['faults'] if f['kind'] == 'restart')
    silences = [restart['end'] - restart['start'] + restart['input_s']]
    for burst in (f for f in fig['faults'] if f['kind'] == 'burst'):
        silences += burst['silences_s']
    allowed = sum(WATCHDOG_MIN_S * (2**k - 1) <= s for s in silences for k in range(1, 6))
    resubscribed = fig['counters']['input_resubscribed']
    assert resubscribed <= allowed + 1, (silences, fig['resubscribed_at'], run.stdout)
    # the input's rate in every status is the simulator's 500 Hz (a stop's lost samples over its
    # span of stamps read 8.6 Hz, a burst's 2190 Hz: the self-test ran at them)
    assert fig['sample_rates'] and all(
        abs(float(rate) / 500.0 - 1) < 0.02 for rate in fig['sample_rates']
    ), fig['sample_rates']
    for storm in (f for f in fig['faults'] if f['kind'] == 'storm'):
        assert storm['answered'] == storm['calls'] == 200 and storm['wrong_verdicts'] == 0
    for burst in (f for f in fig['faults'] if f['kind'] == 'burst'):
        # every burst message received or counted; beyond it, only the simulator's samples in
        # flight when it was stopped (at most 0.1 s of them at speed 10: 500; a CI run read 43)
        assert 5001 <= burst['received'] + burst['missing'] <= 5001 + 500, burst
    assert all(fig['identities'].values())
    assert not any(fig['tracebacks'].values())
    # the estimates between faults are the arm's (a run this short holds tens, some of them still
    # near a fault: the share within 2 % is the benchmark's figure, 77-100 % in such runs)
    assert fig['accuracy_n'] >= 20 and fig['accuracy_median'] < 0.01, fig
    # the replayed bag looped, its estimator took every message or counted it; the shaper took
    # every reference and estimate sent to it and kept commanding
    replay, shaper = fig['others']['replay'], fig['others']['shaper']
    assert replay['loops'] >= 3 and replay['estimates'] > 0, replay
    assert replay['received'] + replay['samples_missing'] >= replay['sent_after_its_first']
    assert shaper['references'] == shaper['references_sent'] > 0, shaper
    assert (
        shaper['frequency_estimates'] + shaper['estimates_ignored']
        == shaper['estimates_published']
    )
    # one command a /clock of the simulator (use_sim_time: up to 1 kHz, fewer on a loaded
    # machine, 4879 in 80 s at a load of 13), from the first reference on
    assert shaper['commands_published'] > 1000, shaper
