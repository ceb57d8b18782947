{#- One struct for both languages (flow::testbench::StreamTb) includes its language's file. -#}
{% if vhdl %}{% include "stream_tb.vhd" %}{% else %}{% include "stream_tb.v" %}{% endif %}
