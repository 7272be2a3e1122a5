"""Writes the .pvsm twin of every figure script in this folder: the Python state is the
definition, the saved state is made from it. Run with a plain Python under a virtual X
server, TOPOSPLINE_PLUGIN set:
    TOPOSPLINE_PLUGIN=build/lib/paraview-plugins/TopoSpline/TopoSpline.so \
      xvfb-run -a -s "-screen 0 1280x1024x24" python3 states/make_states.py"""
import glob
import os
import subprocess
import sys

here = os.path.dirname(os.path.abspath(__file__))
for script in sorted(glob.glob(os.path.join(here, "fig*.py"))):
    state = script[:-3] + ".pvsm"
    code = "__file__ = %r\nexec(open(__file__).read())\nSaveState(%r)\n" % (script, state)
    subprocess.run(["pvbatch", "-c", code], check=True)
    print("wrote", state)
