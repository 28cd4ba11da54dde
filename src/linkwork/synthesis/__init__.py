"""Shape-change synthesis (Shamsudin et al. 2013): target profiles, M- and C-segments, the segment-matrix
search, joining the chain and compound segments."""

from linkwork.synthesis.problem import Problem
from linkwork.synthesis.result import (
    Compound,
    DesignScore,
    JoinedProfile,
    SearchStats,
    Segment,
    SynthesisResult,
    TargetProfile,
    target_profile_rows,
    write_target_profiles_csv,
)
from linkwork.synthesis.synthesize import synthesize
from linkwork.synthesis.targets import target_profile, target_profiles

__all__ = [
    "Compound",
    "DesignScore",
    "JoinedProfile",
    "Problem",
    "SearchStats",
    "Segment",
    "SynthesisResult",
    "TargetProfile",
    "synthesize",
    "target_profile",
    "target_profile_rows",
    "target_profiles",
    "write_target_profiles_csv",
]
