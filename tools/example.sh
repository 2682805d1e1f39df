#!/usr/bin/env bash
# Install sphdvi and run the 2D dam-break example end to end (README, command 1).
set -euo pipefail
cd "$(dirname "$0")/.."
python -m pip install -e ".[test]"
# out/dambreak2d may hold an earlier run of the example: --overwrite deletes its results
sphdvi gencase cases/dambreak2d/CaseDambreakVal2D_Def.xml -o out/dambreak2d --overwrite
sphdvi run out/dambreak2d --tmax 0.05 --tout 0.01
sphdvi export out/dambreak2d
