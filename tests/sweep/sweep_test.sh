# Sourced by the sweep test scripts, which all take EXC_SIM SPEC_TEMPLATE SCENE WORK:
# sweep_test_setup "$@" sets sim, template, scene and work, empties WORK and writes WORK/spec.yaml,
# the Monte-Carlo spec cut to 8 cases of 0.3 s on SCENE (an absolute path), so a test's sweeps take
# seconds; fail MESSAGE ends the test.
sweep_test_setup() {
  sim=$1 template=$2 scene=$3 work=$4
  rm -rf "$work"; mkdir -p "$work"
  sed -e 's/cases: 1000/cases: 8/' -e "s|../scenes/dig.yaml|$scene|" "$template" > "$work/spec.yaml"
  echo "  duration: 0.3" >> "$work/spec.yaml"
}
fail() { echo "FAIL: $*" >&2; exit 1; }
