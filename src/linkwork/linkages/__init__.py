"""Built-in linkages: named constructors registered in :data:`linkwork.linkages.registry.REGISTRY`.

Importing this package registers every built-in (each module registers itself on import).
"""

from linkwork.linkages import bennett as _bennett  # noqa: F401
from linkwork.linkages import bricard as _bricard  # noqa: F401
from linkwork.linkages import four_bar as _four_bar  # noqa: F401
from linkwork.linkages import goldberg as _goldberg  # noqa: F401
from linkwork.linkages import guest as _guest  # noqa: F401
from linkwork.linkages import hedgepeth as _hedgepeth  # noqa: F401
from linkwork.linkages import hedgepeth_rods as _hedgepeth_rods  # noqa: F401
from linkwork.linkages import rect_frame as _rect_frame  # noqa: F401
from linkwork.linkages import sarrus as _sarrus  # noqa: F401
from linkwork.linkages import slider_crank as _slider_crank  # noqa: F401
from linkwork.linkages.hedgepeth import deployed_angle, hedgepeth
from linkwork.linkages.hedgepeth_rods import hedgepeth_rods
from linkwork.linkages.registry import REGISTRY, LinkageEntry, Param, get

__all__ = ["REGISTRY", "LinkageEntry", "Param", "deployed_angle", "get", "hedgepeth", "hedgepeth_rods"]
