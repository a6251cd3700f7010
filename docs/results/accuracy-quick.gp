# made by build/bench/accuracy: the time-error plane of the fast GPU path against the CPU reference
# run in its folder: gnuplot accuracy-quick.gp
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
  set terminal pngcairo size 1200,800 enhanced font 'sans,11'
} else {
  set terminal png size 1200,800
}
set output 'accuracy-quick.png'
set title "veil fast path vs CPU reference (single scattering), 64x48, llvmpipe (LLVM 15.0.6, 256 bits), --quick" noenhanced
set logscale xy
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set xlabel 'fast path: wall time of one uncached frame, ms (inject + propagate + march; median)'
set ylabel 'error against the reference (single scattering): rel_rmse per pixel' noenhanced
set key outside right top noenhanced samplen 2
set format y '%g'
$all0 << EOD
13.35 0.00518483 "res=32"
74.27 0.00516964 "res=64"
78.33 0.00516846 "step=1+res=64"
120.4 0.0220566 "res=32+jacobi-corrected"
269.9 0.00516323 "step=4"
321.5 0.00516963 "default"
344.2 0.00517003 "semi-lagrangian"
368.8 0.00516927 "step=1"
412.8 0.00516949 "step=0.25"
524.5 0.00816782 "sweep"
EOD
$front0 << EOD
13.35 0.00518483 "res=32"
EOD
$default0 << EOD
321.5 0.00516963
EOD
$all1 << EOD
56.01 0.149786 "res=32"
74.11 0.337031 "res=32+jacobi-corrected"
139.2 0.0837323 "step=1+res=64"
184.4 0.08321 "res=64"
465 0.0771229 "step=4"
481.1 0.0768522 "step=1"
525.4 0.0769026 "step=0.25"
527 0.0769033 "default"
550.1 0.0762592 "semi-lagrangian"
554.4 0.146713 "sweep"
EOD
$front1 << EOD
56.01 0.149786 "res=32"
139.2 0.0837323 "step=1+res=64"
465 0.0771229 "step=4"
EOD
$default1 << EOD
527 0.0769033
EOD
$all2 << EOD
196.8 0.0345313 "res=32"
212.4 0.0372381 "res=32+jacobi-corrected"
254.6 0.0132087 "res=64"
267.6 0.0130577 "step=1+res=64"
299.4 0.00838114 "step=4"
315.5 0.00788236 "default"
319.6 0.00789009 "step=1"
358.2 0.00788064 "step=0.25"
360.5 0.00788075 "semi-lagrangian"
408 0.0090203 "sweep"
EOD
$front2 << EOD
196.8 0.0345313 "res=32"
254.6 0.0132087 "res=64"
299.4 0.00838114 "step=4"
315.5 0.00788236 "default"
EOD
$default2 << EOD
315.5 0.00788236
EOD
plot \
  NaN with lines lw 2 lc rgb 'black' title 'Pareto front', \
  NaN with points pt 6 ps 2.6 lw 2 lc rgb 'black' title 'default setting', \
  NaN with lines dt 2 lc rgb 'black' title 'reference noise (same scale)', \
  $all0 using 1:2 with points pt 7 ps 1.2 lc rgb '#1f77b4' title 'homogeneous', \
  $front0 using 1:2 with lines lw 2 lc rgb '#1f77b4' notitle, \
  $front0 using 1:2:3 with labels font ',8' offset char 0.6,0.6 left tc rgb '#1f77b4' notitle, \
  $default0 using 1:2 with points pt 6 ps 2.6 lw 2 lc rgb '#1f77b4' notitle, \
  0.00507581 with lines dt 2 lw 1 lc rgb '#1f77b4' notitle, \
  $all1 using 1:2 with points pt 7 ps 1.2 lc rgb '#d62728' title 'rbf-fog', \
  $front1 using 1:2 with lines lw 2 lc rgb '#d62728' notitle, \
  $front1 using 1:2:3 with labels font ',8' offset char 0.6,0.6 left tc rgb '#d62728' notitle, \
  $default1 using 1:2 with points pt 6 ps 2.6 lw 2 lc rgb '#d62728' notitle, \
  0.072836 with lines dt 2 lw 1 lc rgb '#d62728' notitle, \
  $all2 using 1:2 with points pt 7 ps 1.2 lc rgb '#2ca02c' title 'vdb-smoke', \
  $front2 using 1:2 with lines lw 2 lc rgb '#2ca02c' notitle, \
  $front2 using 1:2:3 with labels font ',8' offset char 0.6,0.6 left tc rgb '#2ca02c' notitle, \
  $default2 using 1:2 with points pt 6 ps 2.6 lw 2 lc rgb '#2ca02c' notitle, \
  0.00741249 with lines dt 2 lw 1 lc rgb '#2ca02c' notitle
