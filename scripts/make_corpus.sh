#!/usr/bin/env bash
# The KiCad board corpus (issue 38; docs/import.md, "Large assemblies: the KiCad board corpus"): three
# large STEP assemblies made of real component models, for import benchmarks
# (scripts/import_peer_bench.sh). Kept out of git and out of the default tests.
#   1. unpacks the .step models of Debian's kicad-packages3d (379 MB; a copy in /tmp/kicad or
#      $KICAD_DEB is used when there) into the ignored data/external/kicad/ (once: a stamp file);
#   2. builds make_board_assembly (bench/) if needed;
#   3. writes out/corpus/board-{5,40,150}mb.step: about 5 MB, 40 MB and 150 MB; each model chosen
#      by its place in its family's sorted list, each board by a fixed seed, so the files are the
#      same on every run (a board is made again only when its models, counts or the generator's
#      source changed).
#   bash scripts/make_corpus.sh [BUILD_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
models=$root/data/external/kicad
out=$root/out/corpus
stamp=$models/.unpacked
export LC_ALL=C  # the sorted model lists, hence the boards, must not depend on the locale

# --- 1. the models ---
if [ ! -f "$stamp" ]; then
  deb=${KICAD_DEB:-}
  if [ -z "$deb" ]; then deb=$(find /tmp/kicad -maxdepth 1 -name 'kicad-packages3d_*_all.deb' 2>/dev/null | sort | tail -n 1 || true); fi
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  if [ -z "$deb" ]; then
    echo "make_corpus: downloading kicad-packages3d (379 MB)" >&2
    chmod 755 "$work"  # apt's sandbox user must be able to write the download here
    (cd "$work" && apt-get download -qq kicad-packages3d >/dev/null)
    deb=$(ls "$work"/kicad-packages3d_*_all.deb)
  fi
  echo "make_corpus: unpacking the .step models of $(basename "$deb") into data/external/kicad" >&2
  rm -rf "$models.partial"
  mkdir -p "$models.partial"
  # ./usr/share/kicad/3dmodels/FAMILY.3dshapes/MODEL.step -> FAMILY.3dshapes/MODEL.step
  dpkg-deb --fsys-tarfile "$deb" | tar -x -C "$models.partial" --strip-components=5 --wildcards '*.step'
  echo "$(basename "$deb"): $(find "$models.partial" -name '*.step' | wc -l) .step files" >"$models.partial/.unpacked"
  rm -rf "$models"
  mv "$models.partial" "$models"  # the stamp arrives with the whole tree, never before it
fi

# --- 2. the generator ---
if [ ! -f "$build/CMakeCache.txt" ]; then
  generator=()
  if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
  # The generator needs OCCT alone: no tools, tests or examples.
  cmake -S "$root" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DCADCLASH_BUILD_BENCH=ON \
    -DCADCLASH_BUILD_TESTS=OFF -DCADCLASH_BUILD_EXAMPLES=OFF -DCADCLASH_BUILD_TOOLS=OFF >/dev/null
elif ! grep -q '^CADCLASH_BUILD_BENCH:BOOL=ON' "$build/CMakeCache.txt"; then
  cmake -S "$root" -B "$build" -DCADCLASH_BUILD_BENCH=ON >/dev/null
fi
cmake --build "$build" --target make_board_assembly >/dev/null
generator_exe=$build/bench/make_board_assembly

# --- 3. the boards ---
# pick FAMILY COUNT: COUNT models of data/external/kicad/FAMILY.3dshapes, evenly spread over its
# sorted list (the middle of each of COUNT equal slices), so small and large variants both come in.
pick() {
  local files n
  mapfile -t files < <(find "$models/$1.3dshapes" -maxdepth 1 -name '*.step' | sort)
  n=${#files[@]}
  for ((i = 0; i < $2 && i < n; i++)); do echo "${files[$(((2 * i + 1) * n / (2 * $2)))]}"; done
}
# The boards: name, placements, seed, then FAMILY:COUNT. Passives, LEDs, diodes and crystals are
# many and small; packages (SOIC, DIP, QFP, TO/SOT) and connectors (pin headers are large: every pin
# is modelled) are fewer and larger, as on real boards. The counts are tuned so the sizes land.
boards=(
  "board-5mb 150 5 Resistor_SMD:3 Resistor_THT:3 Capacitor_SMD:2 Capacitor_THT:3 LED_THT:2 LED_SMD:1
   Diode_THT:2 Crystal:1 Package_TO_SOT_SMD:1 Package_TO_SOT_THT:1 Package_SO:1"
  "board-40mb 170 40 Resistor_SMD:4 Resistor_THT:6 Capacitor_SMD:5 Capacitor_THT:7 LED_THT:4 LED_SMD:2
   Diode_THT:3 Diode_SMD:2 Crystal:3 Inductor_SMD:2 Package_TO_SOT_SMD:4 Package_TO_SOT_THT:3
   Package_SO:4 Package_DIP:4 Package_QFP:2 Connector_PinHeader_2.54mm:2 Connector_JST:3"
  "board-150mb 520 150 Resistor_SMD:12 Resistor_THT:18 Capacitor_SMD:18 Capacitor_THT:28
   Capacitor_Tantalum_SMD:6 LED_THT:14 LED_SMD:8 Diode_THT:14 Diode_SMD:8 Crystal:12 Oscillator:3
   Inductor_SMD:8 Inductor_THT:8 Fuse:6 Package_TO_SOT_SMD:14 Package_TO_SOT_THT:12 Package_SO:12
   Package_DIP:10 Package_QFP:3 Package_DFN_QFN:8 Connector_PinHeader_2.54mm:6 Connector_PinSocket_2.54mm:4
   Connector_JST:6 Connector_Molex:2 Button_Switch_THT:4 Relay_THT:2 TerminalBlock_Phoenix:3"
)
mkdir -p "$out"
start=$(date +%s)
rows=()
for spec in "${boards[@]}"; do
  read -r -a f <<<"${spec//$'\n'/ }"  # the spec's lines as one
  name=${f[0]} placements=${f[1]} seed=${f[2]}
  list=$out/$name.models
  for fc in "${f[@]:3}"; do pick "${fc%:*}" "${fc#*:}"; done >"$list"
  summary=$out/$name.summary
  key="key $placements $seed $(cat "$list" "$root/bench/make_board_assembly.cpp" | sha256sum | cut -c1-16)"
  if [ ! -f "$out/$name.step" ] || [ "$(sed -n 's/^key /key /p' "$summary" 2>/dev/null)" != "$key" ]; then
    echo "make_corpus: writing $name.step ($(wc -l <"$list") models, $placements placements)" >&2
    t0=$(date +%s)
    # Written next to its final name and renamed, so a board that is there is whole.
    "$generator_exe" --out "$out/$name.tmp.step" --placements "$placements" --seed "$seed" --name "${name%-*}" \
      --list "$list" | sed "s|$name.tmp.step|$name.step|" >"$summary.tmp"
    mv "$out/$name.tmp.step" "$out/$name.step"
    printf 'seconds %s\n%s\n' "$(($(date +%s) - t0))" "$key" >>"$summary.tmp"
    mv "$summary.tmp" "$summary"
  fi
  rows+=("$name $summary")
done

echo
echo "| file | size MB | components | distinct models | faces | holes | generated in s |"
echo "|---|---|---|---|---|---|---|"
for r in "${rows[@]}"; do
  read -r name summary <<<"$r"
  # "OUT: N components, M distinct models, F faces written, S MB (B bytes), H holes, board ..."
  line=$(head -n 1 "$summary")
  components=$(sed -E 's/.*: ([0-9]+) components.*/\1/' <<<"$line")
  distinct=$(sed -E 's/.* ([0-9]+) distinct models.*/\1/' <<<"$line")
  faces=$(sed -E 's/.* ([0-9]+) faces written.*/\1/' <<<"$line")
  holes=$(sed -E 's/.* ([0-9]+) holes.*/\1/' <<<"$line")
  mb=$(awk -v b="$(stat -c %s "$out/$name.step")" 'BEGIN { printf "%.1f", b / 1e6 }')
  echo "| out/corpus/$name.step | $mb | $components | $distinct | $faces | $holes | $(sed -n 's/^seconds //p' "$summary") |"
done
echo "(made in $(($(date +%s) - start)) s)" >&2
