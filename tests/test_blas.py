"""imgmtf._blas: the module named to load is imported before BLAS is limited, except in a process on one
thread for good (a worker), which imports it only where it is used."""
import subprocess
import sys


def test_the_module_to_load_is_imported_unless_one_thread_for_good():
    code = ("import sys, imgmtf._blas as b\n"
            "if sys.argv[1] == 'worker':\n"
            "    b.one_thread_for_good()\n"
            "with b.one_blas_thread(load='colorsys'):\n"
            "    print('colorsys' in sys.modules)")
    for role, loaded in (("caller", "True"), ("worker", "False")):
        out = subprocess.run([sys.executable, "-c", code, role], capture_output=True, text=True, timeout=60)
        assert out.returncode == 0 and out.stdout.split() == [loaded], out.stderr
