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
13.47 0.00749812 "res=32"
57.11 0.00747255 "step=1+res=64"
65.87 0.00747222 "res=64"
94.03 0.0230809 "res=32+jacobi-corrected"
392.2 0.00746966 "step=1"
400.1 0.00746739 "step=4"
418.4 0.00746956 "default"
438.3 0.00746962 "step=0.25"
603.6 0.0100478 "sweep"
EOD
$front0 << EOD
13.47 0.00749812 "res=32"
EOD
$default0 << EOD
418.4 0.00746956
EOD
$all1 << EOD
71.81 0.168615 "res=32"
76.02 0.335718 "res=32+jacobi-corrected"
147.5 0.0907123 "step=1+res=64"
389 0.0902574 "res=64"
541.6 0.0816903 "step=1"
546.4 0.0818621 "step=4"
562.7 0.0818457 "default"
608.6 0.0818365 "step=0.25"
628.9 0.145267 "sweep"
EOD
$front1 << EOD
71.81 0.168615 "res=32"
147.5 0.0907123 "step=1+res=64"
541.6 0.0816903 "step=1"
EOD
$default1 << EOD
562.7 0.0818457
EOD
$all2 << EOD
209.1 0.0346583 "res=32"
273.6 0.0137228 "res=64"
277.8 0.0135845 "step=1+res=64"
292.7 0.0374126 "res=32+jacobi-corrected"
349.3 0.00861421 "step=0.25"
352 0.00861305 "step=1"
370.9 0.00894971 "step=4"
411.3 0.00861355 "default"
435.4 0.00974852 "sweep"
EOD
$front2 << EOD
209.1 0.0346583 "res=32"
273.6 0.0137228 "res=64"
349.3 0.00861421 "step=0.25"
EOD
$default2 << EOD
411.3 0.00861355
EOD
plot \
  NaN with lines lw 2 lc rgb 'black' title 'Pareto front', \
  NaN with points pt 6 ps 2.6 lw 2 lc rgb 'black' title 'default setting', \
  NaN with lines dt 2 lc rgb 'black' title 'reference noise (same scale)', \
  $all0 using 1:2 with points pt 7 ps 1.2 lc rgb '#1f77b4' title 'homogeneous', \
  $front0 using 1:2 with lines lw 2 lc rgb '#1f77b4' notitle, \
  $front0 using 1:2:3 with labels font ',8' offset char 0.6,0.6 left tc rgb '#1f77b4' notitle, \
  $default0 using 1:2 with points pt 6 ps 2.6 lw 2 lc rgb '#1f77b4' notitle, \
  0.0072781 with lines dt 2 lw 1 lc rgb '#1f77b4' notitle, \
  $all1 using 1:2 with points pt 7 ps 1.2 lc rgb '#d62728' title 'rbf-fog', \
  $front1 using 1:2 with lines lw 2 lc rgb '#d62728' notitle, \
  $front1 using 1:2:3 with labels font ',8' offset char 0.6,0.6 left tc rgb '#d62728' notitle, \
  $default1 using 1:2 with points pt 6 ps 2.6 lw 2 lc rgb '#d62728' notitle, \
  0.0762419 with lines dt 2 lw 1 lc rgb '#d62728' notitle, \
  $all2 using 1:2 with points pt 7 ps 1.2 lc rgb '#2ca02c' title 'vdb-smoke', \
  $front2 using 1:2 with lines lw 2 lc rgb '#2ca02c' notitle, \
  $front2 using 1:2:3 with labels font ',8' offset char 0.6,0.6 left tc rgb '#2ca02c' notitle, \
  $default2 using 1:2 with points pt 6 ps 2.6 lw 2 lc rgb '#2ca02c' notitle, \
  0.00814641 with lines dt 2 lw 1 lc rgb '#2ca02c' notitle
