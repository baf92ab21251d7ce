# long_run.png, made by bench/report_long_run (its data: long_run.csv):
#   build/bench/report_long_run --steps 1000000 --dt 0.01 --out bench/results
set terminal pngcairo size 1500,900 font ',10'
set output 'bench/results/long_run.png'
set datafile separator ','
set logscale xy
set format y '10^{%L}'
set format x '10^{%L}'
set xlabel 'simulated time [s]'
set ylabel 'max relative work-balance error so far'
set key top left
set multiplot layout 2,2
set title 'disk (equal CPU per simulated second)'
plot 'bench/results/long_run.csv' using (strcol(1) eq 'disk' && strcol(2) eq 'leapfrog' ? $4 : 1/0):5 with linespoints title 'leapfrog', 'bench/results/long_run.csv' using (strcol(1) eq 'disk' && strcol(2) eq 'rk4' ? $4 : 1/0):5 with linespoints title 'rk4', 'bench/results/long_run.csv' using (strcol(1) eq 'disk' && strcol(2) eq 'euler' ? $4 : 1/0):5 with linespoints title 'euler'
set title 'sleigh (equal CPU per simulated second)'
plot 'bench/results/long_run.csv' using (strcol(1) eq 'sleigh' && strcol(2) eq 'leapfrog' ? $4 : 1/0):5 with linespoints title 'leapfrog', 'bench/results/long_run.csv' using (strcol(1) eq 'sleigh' && strcol(2) eq 'rk4' ? $4 : 1/0):5 with linespoints title 'rk4', 'bench/results/long_run.csv' using (strcol(1) eq 'sleigh' && strcol(2) eq 'euler' ? $4 : 1/0):5 with linespoints title 'euler'
set title 'turntable (equal CPU per simulated second)'
plot 'bench/results/long_run.csv' using (strcol(1) eq 'turntable' && strcol(2) eq 'leapfrog' ? $4 : 1/0):5 with linespoints title 'leapfrog', 'bench/results/long_run.csv' using (strcol(1) eq 'turntable' && strcol(2) eq 'rk4' ? $4 : 1/0):5 with linespoints title 'rk4', 'bench/results/long_run.csv' using (strcol(1) eq 'turntable' && strcol(2) eq 'euler' ? $4 : 1/0):5 with linespoints title 'euler'
set title 'springs (equal CPU per simulated second)'
plot 'bench/results/long_run.csv' using (strcol(1) eq 'springs' && strcol(2) eq 'leapfrog' ? $4 : 1/0):5 with linespoints title 'leapfrog', 'bench/results/long_run.csv' using (strcol(1) eq 'springs' && strcol(2) eq 'rk4' ? $4 : 1/0):5 with linespoints title 'rk4', 'bench/results/long_run.csv' using (strcol(1) eq 'springs' && strcol(2) eq 'euler' ? $4 : 1/0):5 with linespoints title 'euler'
unset multiplot
