"""Studies at scale: imperfection sensitivity by Monte Carlo (``linkwork robustness``) and parameter studies
(``linkwork sweep``), run as chunked Dask tasks (:mod:`linkwork.studies.engine`)."""
