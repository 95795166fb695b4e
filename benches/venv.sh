# The one virtualenv setup of the benches' Python comparisons (run_numpy.sh, run_gtsam.sh,
# run_rosbags.sh source it). Each comparison has a virtualenv of its own, so its packages
# never meet another's.
#
# bench_venv VENV IMPORTS PACKAGE...
#   Makes VENV (python3 -m venv, then a current pip) unless it exists, and installs
#   PACKAGE... with pip unless `import IMPORTS` already works in it.

bench_venv() {
    local venv="$1" imports="$2"
    shift 2
    if [ ! -x "$venv/bin/python" ]; then
        mkdir -p "$(dirname "$venv")"
        python3 -m venv "$venv"
        "$venv/bin/python" -m pip install --quiet --upgrade pip
    fi
    if ! "$venv/bin/python" -c "import $imports" 2>/dev/null; then
        "$venv/bin/python" -m pip install --quiet "$@"
    fi
}
