#!/usr/bin/env bash
# Report weights kept in git history, not in the working tree (session 76): every file that travels to a lent GPU
# machine counts against its 64 MiB, and these three (45.6 MB) had pushed the tracked tree to 90.7 MB, so no device
# call could start. The report scripts that name them (s42-s75) need them back first; this restores them bit for bit.
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
