#!/usr/bin/env bash
# Report weights and per-sample JSON reports kept in git history, not in the working tree (session 76): every file that
# travels to a lent GPU machine counts against its 64 MiB, and these (45.6 MB of weights, 12.1 MB of env_response
# JSON) had pushed the tracked tree to 90.7 MB, so no device call could start. The report scripts that name them
# (s27-s75) need them back first; this restores them bit for bit (their report.md summaries stay in the tree).
# Usage: bash scripts/restore_report_weights.sh   (from the repository root; needs the full history)
set -euo pipefail
cd "$(dirname "$0")/.."
restore() {  # commit path sha256-prefix
  if [ ! -f "$2" ]; then
    mkdir -p "$(dirname "$2")"
    git show "$1:$2" > "$2.part" && mv "$2.part" "$2"
  fi
  sha256sum "$2" | grep -q "^$3" || { echo "restore_report_weights: $2 does not hash to $3..." >&2; exit 1; }
  echo "$2 ok"
}
restore 4072d3a reports/training/s63_deepen/G63_model/model.safetensors acfc672d692a4148
restore ef977e8 reports/training/s45_gravity_confirm/K55_model/model.safetensors af6fb20e81237ae9
restore 6a881f2 reports/training/s55_reference/J40m_sa_adapters.safetensors e0e7d77d303cfd2a
restore d05cbae 'reports/experiments/env_response/report.json' eb3af8be6c75a8a5
restore fa90b05 'reports/experiments/s26_default/env_response/report.json' 8fc554db5869148d
restore 3be6ee5 'reports/training/s27_pairs/env_response/report.json' 1b8dddbbc9c2cb4a
restore 3be6ee5 'reports/training/s27_pairs/env_response_seed100/report.json' 225ac77167245cb8
restore 4ec5b0d 'reports/training/s28_gpu_adapters/env_response/SimDiff_GPU_pair10__α___0.5.json' 1478f9b7b410f7bc
restore 4ec5b0d 'reports/training/s28_gpu_adapters/env_response/SimDiff_GPU_pair30__α___0.5.json' 6356d3c7c9238ddc
restore 0f8ad48 'reports/training/s28_gpu_adapters/env_response_flight/SimDiff_GPU_pair10f__α___0.5.json' 7e131d941b82d79e
restore 0f8ad48 'reports/training/s28_gpu_adapters/env_response_flight/SimDiff_GPU_pair10f__α___1.json' bb6f3c55e6e15c19
restore 3f24dad 'reports/training/s76_lambda/X93_model/model.safetensors' 856504f9169ba456
restore 96adcbf 'reports/training/s78_captioned/X95_model/model.safetensors' 5801f52673e8d161
restore 7d049c1 'reports/training/s79_refit/X96_model/model.safetensors' bea4733bc95c8950
