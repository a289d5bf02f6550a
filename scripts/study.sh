#!/usr/bin/env bash
# The second main job: sets up and builds (scripts/setup.sh), then runs the paper's pilot study
# (FrictionStudy.pilot: three mappings, friction off then on) with five simulated participants,
# headless, on a realtime server (JACK's dummy driver, no sound card), and writes the sessions and
# the report (Markdown, PNG, CSV) into out/study/.
# Usage: scripts/study.sh [--out DIR] [--participants 5] [--explore-s S]
#   --explore-s caps each simulated exploration at S seconds (the CI's short run); without it each
#   participant explores until the coverage criterion is met or its round of speeds is over.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
# The report's paired t test (python/kfharness/study_report.py) and the threshold fits: scipy.
source scripts/packages.sh
kf_install_missing python3-scipy
source scripts/env.sh
"$KF_PYTHON" scripts/study/study_job.py "$@"
