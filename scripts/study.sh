#!/usr/bin/env bash
# The second main job: sets up and builds (scripts/setup.sh), then runs the paper's pilot study
# (FrictionStudy.pilot: three mappings, friction off then on) and its threshold part (a friction
# difference, the sound-to-force asynchrony, a grating period: FrictionStudy.thresholdConditions)
# with five simulated participants side by side, headless, on a realtime server (JACK's dummy
# driver, no sound card), and writes the sessions and the report (FrictionStudy.report: Markdown,
# PNG, CSV) into out/study/.
# Usage: scripts/study.sh [--out DIR] [--participants 5] [--explore-s S] [--trials 40] [--interval-s 1.5]
#                         [--gap-s 0.5]
#   --explore-s caps each simulated exploration at S seconds (the CI's short run); without it each
#   participant explores until the coverage criterion is met or its round of speeds is over.
#   --trials: trials of each threshold experiment (0: no threshold part); --interval-s and --gap-s:
#   each trial's two intervals and the gap after each (the CI's short run shortens them).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
# The report (the extension's python/kfstudy) needs scipy and pandas beside the main job's
# numpy, matplotlib and soundfile.
source scripts/packages.sh
kf_install_missing python3-scipy python3-pandas
source scripts/env.sh
# exec: a signal sent to this script reaches the job, which stops what it started.
exec "$KF_PYTHON" scripts/study/study_job.py "$@"
