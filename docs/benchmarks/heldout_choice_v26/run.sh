# From this folder, with the checkout's shaped-es on PATH (PYTHONPATH=. for md_bodies); ~12 min each, inline.
shaped-es benchmark --env md_bodies:GridMD-v0 --methods shaped,vanilla --seeds 10 --generations 40 --executor inline --no-estimate --quiet --threshold 8.24 --out bench_grid
shaped-es benchmark --env md_bodies:Thrusters-v0 --methods shaped,vanilla --seeds 10 --generations 40 --executor inline --no-estimate --quiet --threshold 7.27 --out bench_thr
python table.py bench_grid 8.24 10.0 > table_grid.txt
python table.py bench_thr 7.27 9.0 10.0 > table_thr.txt
