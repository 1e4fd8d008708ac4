#!/bin/bash
# planted_includes.sh CHECKER ARCHITECTURE_MD WORK: the include-rules check can fail. In a scratch
# source tree with the real docs/architecture.md, a clean tree passes (the control: among them
# firmware/control/'s rooms each including the rooms below it, and its top including them); then an
# include up a floor (hal/ including the plant), an include that names no file, a source in a folder
# the map does not cover, and up a floor inside firmware/control/ (a law including the controller's
# settings at control/'s top, the estimation room including a law, the law interface including the
# settings beside it) must each fail the check, named by file:line.
set -u
checker=$1 doc=$2 work=$3
control=$work/firmware/control
rm -rf "$work" && mkdir -p "$work/docs" "$work/hal" "$work/sim_plant" "$work/firmware/model" \
  "$control/laws" "$control/estimation" "$control/task" "$control/actuation" || exit 1
cp "$doc" "$work/docs/architecture.md" || exit 1
printf '#pragma once\n#include "model/machine.hpp"\n' > "$work/sim_plant/plant.hpp"
printf '#pragma once\n' > "$work/firmware/model/machine.hpp"
printf '#pragma once\n#include <cstdint>\n' > "$work/hal/can_codec.hpp"
printf '#pragma once\n#include "model/machine.hpp"\n' > "$control/control_types.hpp"
printf '#pragma once\n#include "control/control_types.hpp"\n' > "$control/estimation/soil_contact.hpp"
printf '#pragma once\n#include "model/machine.hpp"\n' > "$control/task/task.hpp"
printf '#pragma once\n#include "control/estimation/soil_contact.hpp"\n#include "control/task/task.hpp"\n' > "$control/laws/pid.hpp"
printf '#pragma once\n#include "control/laws/pid.hpp"\n' > "$control/actuation/actuation_stage.hpp"
printf '#pragma once\n#include "control/actuation/actuation_stage.hpp"\n#include "control/laws/pid.hpp"\n' > "$control/controller_config.hpp"

out=$(/usr/bin/python3 "$checker" "$work" 2>&1); rc=$?
printf 'clean tree (rc %d):\n%s\n' "$rc" "$out"
[ "$rc" -eq 0 ] || { echo "FAIL: the clean scratch tree did not pass"; exit 1; }

printf '#pragma once\n#include <cstdint>\n#include "sim_plant/plant.hpp"\n' > "$work/hal/can_codec.hpp"
printf '#pragma once\n#include "model/no_such_header.hpp"\n' > "$work/sim_plant/soil.hpp"
mkdir -p "$work/off_the_map" && printf 'int x;\n' > "$work/off_the_map/thing.cpp"
printf '#pragma once\n#include "control/estimation/soil_contact.hpp"\n#include "control/controller_config.hpp"\n' > "$control/laws/slotine_li.hpp"
printf '#pragma once\n#include "control/laws/pid.hpp"\n' > "$control/estimation/soil_identification.hpp"
printf '#pragma once\n#include "model/machine.hpp"\n#include "control/controller_config.hpp"\n' > "$control/control_types.hpp"
out=$(/usr/bin/python3 "$checker" "$work" 2>&1); rc=$?
printf 'planted tree (rc %d):\n%s\n' "$rc" "$out"
[ "$rc" -eq 1 ] || { echo "FAIL: the planted tree exited $rc, not 1"; exit 1; }
status=0
for expected in 'hal/can_codec.hpp:3: #include "sim_plant/plant.hpp"' 'sim_plant/soil.hpp:2: #include "model/no_such_header.hpp"' \
                'off_the_map/thing.cpp:1: not on the map' \
                'firmware/control/laws/slotine_li.hpp:3: #include "control/controller_config.hpp"' \
                'firmware/control/estimation/soil_identification.hpp:2: #include "control/laws/pid.hpp"' \
                'firmware/control/control_types.hpp:3: #include "control/controller_config.hpp"' ': 6 not allowed'; do
  grep -qF -- "$expected" <<< "$out" || { echo "FAIL: the report does not name: $expected"; status=1; }
done
exit $status
