{#- One struct for both languages (verify::memory_hdl::MemModel) includes its language's file. -#}
{% if vhdl %}{% include "axi_mem_model.vhd" %}{% else %}{% include "axi_mem_model.v" %}{% endif %}
