"""Exports of a traced mechanism to other programs: solids for 3-D printing (STL, 3MF) and a model for the MuJoCo
simulator (MJCF). :mod:`linkwork.export.trace_folder` reads back what ``linkwork trace --out`` wrote."""
