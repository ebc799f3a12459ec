"""The optional C kernels (tanktool/_kernels.c); everything else is in pyproject.toml.

The extension is optional: without a C compiler or Python's headers the build goes on
without it and tanktool uses its numpy code instead (tanktool/geometry/kernels.py),
with identical results, only slower.
"""

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext


class OptionalBuildExt(build_ext):
    """build_ext that warns instead of failing when the kernels cannot be compiled."""

    def run(self):
        try:
            super().run()
        except Exception as e:  # no compiler at all (setuptools raises before compiling)
            self.warn(f"tanktool._kernels not built ({e}); the numpy code is used instead")

    def build_extension(self, ext):
        try:
            super().build_extension(ext)
        except Exception as e:  # a compiler that fails, missing Python.h
            self.warn(f"tanktool._kernels not built ({e}); the numpy code is used instead")


setup(
    # -ffp-contract=off: no fused multiply-adds, the rasteriser's sums are numpy's
    ext_modules=[Extension("tanktool._kernels", ["tanktool/_kernels.c", "tanktool/_kernels_raster.c",
                                                      "tanktool/_kernels_grid.c", "tanktool/_kernels_surface.c",
                                                      "tanktool/_kernels_ground.c", "tanktool/_kernels_faces.c",
                                                      "tanktool/_kernels_path.c"],
                           depends=["tanktool/_kernels.h"], extra_compile_args=["-O2", "-ffp-contract=off"],
                           optional=True)],
    cmdclass={"build_ext": OptionalBuildExt},
)
