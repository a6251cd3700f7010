# made by build/bench/accuracy: the time-error plane of the fast GPU path against the CPU reference
# run in its folder: gnuplot accuracy.gp
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
  set terminal pngcairo size 1200,800 enhanced font 'sans,11'
} else {
  set terminal png size 1200,800
}
set output 'accuracy.png'
set title "veil fast path vs CPU reference (single scattering), 96x72, llvmpipe (LLVM 15.0.6, 256 bits)" noenhanced
set logscale xy
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set xlabel 'fast path: wall time of one uncached frame, ms (inject + propagate + march; median)'
set ylabel 'error against the reference (single scattering): rel_rmse per pixel' noenhanced
set key outside right top noenhanced samplen 2
set format y '%g'
$all0 << EOD
30.34 0.00893569 "step=2+res=32"
63.98 0.00518664 "res=32"
243.2 0.00513244 "res=64"
276.3 0.00512099 "step=1+res=64"
361.3 0.137683 "res=32+jacobi"
1411 0.00512433 "step=1"
1417 0.00513706 "step=2"
1530 0.00512449 "step=0.125"
1634 0.00512454 "step=0.25"
2071 0.00748155 "step=8"
2074 0.00533401 "step=4"
2078 0.0132632 "step=16"
2163 0.00822257 "sweep"
2367 0.00512465 "default"
7240 0.0140366 "res=64+jacobi-corrected"
7737 0.138158 "res=64+jacobi"
1.025e+04 0.00512328 "step=2+res=256"
1.398e+04 0.00512316 "res=256"
EOD
$front0 << EOD
30.34 0.00893569 "step=2+res=32"
63.98 0.00518664 "res=32"
EOD
$default0 << EOD
2367 0.00512465
EOD
$all1 << EOD
234 0.147823 "res=32"
253.4 0.158008 "step=2+res=32"
441.5 0.469152 "res=32+jacobi"
509 0.0585571 "step=1+res=64"
649.4 0.0579986 "res=64"
1447 0.0465332 "default"
2085 0.242502 "step=16"
2319 0.0464691 "step=1"
2635 0.0469092 "step=2"
2685 0.0475483 "step=4"
2784 0.413287 "res=64+jacobi"
2957 0.228056 "res=64+jacobi-corrected"
3116 0.0465327 "step=0.125"
3134 0.0644875 "step=8"
3656 0.0465332 "step=0.25"
3919 0.141464 "sweep"
9784 0.0457246 "step=2+res=256"
1.631e+04 0.0457768 "res=256"
EOD
$front1 << EOD
234 0.147823 "res=32"
509 0.0585571 "step=1+res=64"
1447 0.0465332 "default"
EOD
$default1 << EOD
1447 0.0465332
EOD
$all2 << EOD
657 0.0415328 "res=32"
883 0.0156248 "res=64"
902.2 0.00625162 "default"
904.6 0.0455473 "step=16"
957.3 0.00679676 "step=4"
1004 0.0157907 "step=8"
1333 0.091085 "res=32+jacobi"
1412 0.0062541 "step=0.25"
1446 0.0417948 "step=2+res=32"
1765 0.00622529 "step=2"
1781 0.00623153 "step=1"
1823 0.0156445 "step=1+res=64"
2092 0.00783256 "sweep"
3393 0.017758 "res=64+jacobi-corrected"
3747 0.0874847 "res=64+jacobi"
4084 0.103571 "step=0.125"
4286 0.00418899 "res=256"
4682 0.0041999 "step=2+res=256"
EOD
$front2 << EOD
657 0.0415328 "res=32"
883 0.0156248 "res=64"
902.2 0.00625162 "default"
4286 0.00418899 "res=256"
EOD
$default2 << EOD
902.2 0.00625162
EOD
plot \
  NaN with lines lw 2 lc rgb 'black' title 'Pareto front', \
  NaN with points pt 6 ps 2.6 lw 2 lc rgb 'black' title 'default setting', \
  NaN with lines dt 2 lc rgb 'black' title 'reference noise (same scale)', \
  $all0 using 1:2 with points pt 7 ps 1.2 lc rgb '#1f77b4' title 'homogeneous', \
  $front0 using 1:2 with lines lw 2 lc rgb '#1f77b4' notitle, \
  $front0 using 1:2:3 with labels font ',8' offset char 0.6,0.6 left tc rgb '#1f77b4' notitle, \
  $default0 using 1:2 with points pt 6 ps 2.6 lw 2 lc rgb '#1f77b4' notitle, \
  0.0050753 with lines dt 2 lw 1 lc rgb '#1f77b4' notitle, \
  $all1 using 1:2 with points pt 7 ps 1.2 lc rgb '#d62728' title 'rbf-fog', \
  $front1 using 1:2 with lines lw 2 lc rgb '#d62728' notitle, \
  $front1 using 1:2:3 with labels font ',8' offset char 0.6,0.6 left tc rgb '#d62728' notitle, \
  $default1 using 1:2 with points pt 6 ps 2.6 lw 2 lc rgb '#d62728' notitle, \
  0.0461466 with lines dt 2 lw 1 lc rgb '#d62728' notitle, \
  $all2 using 1:2 with points pt 7 ps 1.2 lc rgb '#2ca02c' title 'vdb-smoke', \
  $front2 using 1:2 with lines lw 2 lc rgb '#2ca02c' notitle, \
  $front2 using 1:2:3 with labels font ',8' offset char 0.6,0.6 left tc rgb '#2ca02c' notitle, \
  $default2 using 1:2 with points pt 6 ps 2.6 lw 2 lc rgb '#2ca02c' notitle, \
  0.00417736 with lines dt 2 lw 1 lc rgb '#2ca02c' notitle
