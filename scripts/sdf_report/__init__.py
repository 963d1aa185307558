"""sdf_report: the report of stored runs (scripts/make-report).

Modules: schema (the run schema shared with the C++ side, harness/schema/run_schema.json with
its $defs files, and its validator), runs (finding and loading runs), tables, document
(Markdown and self-contained HTML), plots and images (matplotlib figures, reduced image
grids); one module per section: overview (the runs, their machines and checks), sampling
(sampling times and throughput of every run that records them), speedup (thesis Tables
3-1/3-2), analytic (Table 4-1, error versus samples), reconstruction (error tables, sweeps,
image grids), peers (the peer libraries); cli puts them together.
"""
