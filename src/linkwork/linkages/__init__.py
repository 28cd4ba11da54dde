"""Built-in linkages: named constructors registered in :data:`linkwork.linkages.registry.REGISTRY`."""

from linkwork.linkages import hedgepeth as _hedgepeth  # noqa: F401  (registers itself)
from linkwork.linkages.hedgepeth import deployed_angle, hedgepeth
from linkwork.linkages.registry import REGISTRY, LinkageEntry, Param, get

__all__ = ["REGISTRY", "LinkageEntry", "Param", "deployed_angle", "get", "hedgepeth"]
