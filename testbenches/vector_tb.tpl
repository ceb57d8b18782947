{#- One struct for both languages (flow::testbench::VectorTb) includes its language's file. -#}
{% if vhdl %}{% include "vector_tb.vhd" %}{% else %}{% include "vector_tb.v" %}{% endif %}
