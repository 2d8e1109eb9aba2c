#!/usr/bin/env bash
# Runs the reference solver SPlisHSPlasH 2.16 on a scene kept here, with the runner and the
# shared assets of ../shared/anchors/splishsplash (or $SPLISHSPLASH):
#   bench/splishsplash/run.sh SCENE THREADS SECONDS     e.g. run.sh dam_break_1m_dfsph 2 0.1
# SCENE is a file name here without .json; it has exactly the geometry of projfluid's scene of
# the same name without the suffix (built in, or bench/NAME.json): r, lattice, tank. Prints the
# solver's wall time; scenes that export frames write them to the directory given fourth.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ANCHOR=${SPLISHSPLASH:-$HERE/../../../shared/anchors/splishsplash}
[ -x "$ANCHOR/run.sh" ] || { echo "no SPlisHSPlasH runner at $ANCHOR (set SPLISHSPLASH)" >&2; exit 1; }
SCENE=${1:?scene}
# The anchor's runner reads scenes from its own folder: run it from a copy that holds this one.
COPY=$(mktemp -d /tmp/splishsplash-anchor.XXXXXX)
trap 'rm -rf "$COPY"' EXIT
mkdir "$COPY/scenes"
cp "$ANCHOR"/scenes/* "$HERE"/*.json "$COPY/scenes/"
ln -s "$ANCHOR/SPHSimulator" "$ANCHOR/lib" "$COPY/"
cp "$ANCHOR/run.sh" "$COPY/run.sh"
"$COPY/run.sh" "$SCENE" "${@:2}"
