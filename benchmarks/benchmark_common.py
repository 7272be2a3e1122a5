"""What the pvpython benchmarks share: where the plugin and the data are, and a ParaView
session with the plugin loaded and the STDThread backend on 2 threads."""
import os

from paraview.simple import LoadPlugin
from vtkmodules.vtkCommonCore import vtkSMPTools

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
PLUGIN = os.environ.get("TOPOSPLINE_PLUGIN", os.path.join(REPO, "build", "lib", "paraview-plugins", "TopoSpline",
                                                          "TopoSpline.so"))
SHARED = os.environ.get("TOPOSPLINE_SHARED_DATA", os.path.join(REPO, "..", "shared", "data"))


def start(namespace):
    """Loads the plugin's proxies into `namespace` and selects 2 STDThread threads."""
    LoadPlugin(PLUGIN, remote=False, ns=namespace)
    vtkSMPTools.SetBackend("STDThread")
    vtkSMPTools.Initialize(2)


def data_file(name):
    """A data set shipped in tests/data, else in ../shared/data; None when absent."""
    for folder in (os.path.join(REPO, "tests", "data"), SHARED):
        path = os.path.join(folder, name)
        if os.path.exists(path):
            return path
    return None
