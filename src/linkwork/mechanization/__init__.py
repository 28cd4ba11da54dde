"""Mechanization (Shamsudin et al. 2013, Sec. 7): binary links that give the synthesised chain the few degrees
of freedom a designer wants, by rigid-body guidance, verified by tracing with the kinematic core."""

from linkwork.mechanization.assemble import BinaryLink, Design, spec_text
from linkwork.mechanization.chain import ShapeChain, build_chain
from linkwork.mechanization.guidance import (
    Dyad,
    burmester_points,
    centre_point,
    circle_point_curve,
    circle_through,
    fit_circle_point,
)
from linkwork.mechanization.mechanize import Mechanization, mechanize
from linkwork.mechanization.options import GroundRegion, MechanizeOptions, options_from_values
from linkwork.mechanization.report import mechanization_dict, write_mechanization
from linkwork.mechanization.search import MechanizationError
from linkwork.mechanization.verify import ProfileState, Verification, verify

__all__ = [
    "BinaryLink",
    "Design",
    "Dyad",
    "GroundRegion",
    "Mechanization",
    "MechanizationError",
    "MechanizeOptions",
    "ProfileState",
    "ShapeChain",
    "Verification",
    "build_chain",
    "burmester_points",
    "centre_point",
    "circle_point_curve",
    "circle_through",
    "fit_circle_point",
    "mechanization_dict",
    "mechanize",
    "options_from_values",
    "spec_text",
    "verify",
    "write_mechanization",
]
